"""The record of a refinement (`Refinement`) and its arrays built on first use (`Lazy`, `LazyArrays`).

`refine_general` and `refine_templates` build it, `refine` chooses between them; see `refine` for the
construction and the vertex numbering.
"""

import threading
from dataclasses import dataclass

import numpy as np


class Lazy:
    """A value built on first use, exactly once, also when several threads ask for it at the same time.

    ``Lazy(builder)`` calls ``builder()`` on the first `get`; ``Lazy.of(value)`` holds a value already built.
    """

    __slots__ = ("_builder", "_value", "_lock")

    def __init__(self, builder):
        self._builder, self._value, self._lock = builder, None, threading.Lock()

    @classmethod
    def of(cls, value):
        lazy = cls(None)
        lazy._value = value
        return lazy

    def get(self):
        if self._builder is not None:
            with self._lock:
                if self._builder is not None:
                    self._value = self._builder()
                    self._builder = None
        return self._value


@dataclass(frozen=True)
class LazyArrays:
    """The arrays of a `Refinement` that are built only when asked for (each a `Lazy`).

    triangles: (M, 3) int32; triangle_face: (M,) int32; interior_face: (Ni,) int32; interior_bary: (Ni, 3)
    float64; corner_bary: (M, 3, 3) float64; output_edges: ``(edges (K, 2), corner_edges (M, 3))`` int32, or
    None when the construction does not know them (the general path: the mesh writer computes edges);
    corner_slots: ``(slot_face (N,) int64, slot_bary (N, 3) float64, triangle_slots (M, 3) int64)`` where the
    construction numbers each face's vertices once per face (the general path's ring vertices): ``corner_bary ==
    slot_bary[triangle_slots]``, so a corner attribute can be weighed once per slot and gathered; else None.
    """

    triangles: Lazy
    triangle_face: Lazy
    interior_face: Lazy
    interior_bary: Lazy
    corner_bary: Lazy
    output_edges: Lazy | None = None
    corner_slots: Lazy | None = None


@dataclass(frozen=True)
class Refinement:
    """The refined topology of a triangle mesh and the provenance of every output element.

    Output vertex ``i`` is an input vertex for ``i < n_corners``; an edge point for
    ``n_corners <= i < n_corners + len(edge_point_edge)``; an interior point after that.

    faces: (T, 3) int32 input triangles.
    edges: (E, 2) int32 input edges ``(lo, hi)``, the order of the ``edge_levels`` array.
    edge_point_edge: (Ne,) int32 edge of each edge point.
    edge_point_t: (Ne,) float64 parameter from ``edges[e, 0]`` to ``edges[e, 1]``.
    interior_face: (Ni,) int32 face of each interior point.
    interior_bary: (Ni, 3) float64 barycentric coordinates in that face.
    triangles: (M, 3) int32 output triangles, counter-clockwise like their source face, grouped by face.
    triangle_face: (M,) int32 source face of each output triangle.
    corner_bary: (M, 3, 3) float64 barycentric coordinates of each output corner in its source face
        (for per-corner attributes such as UVs, which may differ between the faces of a shared vertex).
    spacing: the spacing used.
    edge_level, edge_segments: (E,) float64 clamped level and int64 segment count of each edge.
    inner_level, inner_segments: (T,) float64 and int64, the same for each face's interior.
    interior_counts: (T,) int64 interior points of each face (they are stored contiguously, face by face).
    n_triangles: M, the number of output triangles.
    """

    n_corners: int
    faces: np.ndarray
    edges: np.ndarray
    edge_point_edge: np.ndarray
    edge_point_t: np.ndarray
    spacing: str
    edge_level: np.ndarray
    edge_segments: np.ndarray
    inner_level: np.ndarray
    inner_segments: np.ndarray
    interior_counts: np.ndarray
    n_triangles: int
    #: The per-output arrays (triangles, provenance, output edges), built on first use.
    arrays: LazyArrays
    #: (T, 3) int32 mesh edge and (T, 3) bool direction flag of each face's local edges (`triangle_edges`).
    face_edges: np.ndarray | None = None
    flipped: np.ndarray | None = None
    #: Class of each face (T,) int64 and the `refine_templates.PatternClass` of each class (set when built per
    #: class).
    face_class: np.ndarray | None = None
    classes: tuple = ()

    @property
    def triangles(self):
        return self.arrays.triangles.get()

    @property
    def triangle_face(self):
        return self.arrays.triangle_face.get()

    @property
    def interior_face(self):
        return self.arrays.interior_face.get()

    @property
    def interior_bary(self):
        return self.arrays.interior_bary.get()

    @property
    def corner_bary(self):
        return self.arrays.corner_bary.get()

    @property
    def has_output_edges(self):
        """True when the refinement knows its output edges (built per pattern class; the general path leaves
        them to the mesh writer)."""
        return self.arrays.output_edges is not None

    def output_edges(self):
        """``(edges (K, 2) int32, corner_edges (M, 3) int32)`` of the output mesh (the edge from corner k to
        corner k + 1 of every output triangle), or None where `has_output_edges` is False."""
        return self.arrays.output_edges.get() if self.has_output_edges else None

    @property
    def edge_point_start(self):
        """(E,) int64 offset of each edge's first point in ``edge_point_edge`` / ``edge_point_t``."""
        counts = np.maximum(self.edge_segments - 1, 0)
        return np.cumsum(counts) - counts

    @property
    def n_vertices(self):
        return self.n_corners + len(self.edge_point_edge) + int(self.interior_counts.sum())

    def interior_template(self, face, start):
        """Barycentrics (P, 3) of the interior points of ``face``, stored from offset ``start``."""
        if self.face_class is not None:
            return self.classes[self.face_class[face]].interior_bary
        return self.interior_bary[start : start + int(self.interior_counts[face])]

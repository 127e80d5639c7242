"""Refinement by pattern class: build each distinct triangle pattern once, then stamp it onto its faces.

A face's refined topology depends only on its three local segment counts and its inner segment count
(plus, with fractional spacing, the levels themselves, which move the points). Uniform levels, and
adaptive levels rounded to powers of two, leave few such classes. For each class the general
construction of `kernels.tessellation.refine` runs on one lone triangle; its output triangles, written in "slots"
(corner, point ``j`` of local edge ``e``, interior point ``i``), are mapped to each face's real vertex
ids with one gather. Vertex numbering, triangle order and barycentrics are those of the general path
(the tests compare both bit for bit for the topology).
"""

from dataclasses import dataclass

import numpy as np

from ..common.rows import put_rows
from ..common.topology import group_by_class, ragged
from .refine_general import edge_points, refine_general
from .refine_general import interior_counts as count_interior
from .refinement import Lazy, LazyArrays, Refinement

#: Use the class path when there are at most this many classes, or at least this many faces per class.
MAX_CLASSES = 64
FACES_PER_CLASS = 64


def pattern_classes(outer_f, outer_n, inner_f, inner_n, spacing):
    """Group faces by refinement pattern.

    outer_f, outer_n: (T, 3) level and segment count of each local edge; inner_f, inner_n: (T,).
    Returns ``(first (C,) int64 a face of each class, inverse (T,) int64 class of each face)``.
    """
    counts = outer_n.astype(np.int64)
    key = ((counts[:, 0] * 65 + counts[:, 1]) * 65 + counts[:, 2]) * 65 + inner_n.astype(np.int64)
    if spacing == "EQUAL":
        if key.min() == key.max():
            return np.zeros(1, np.int64), np.zeros(len(key), np.int64)
        _, first, inverse = np.unique(key, return_index=True, return_inverse=True)
        return first, inverse.reshape(-1)
    rows = np.column_stack([key.astype(np.float64), outer_f, inner_f])
    _, first, inverse = np.unique(rows, axis=0, return_index=True, return_inverse=True)
    return first, inverse.reshape(-1)


def worth_it(classes, n_faces):
    n = len(classes[0])
    return n <= MAX_CLASSES or n * FACES_PER_CLASS <= n_faces


def _lone_pattern(outer_f, outer_n, inner_f, inner_n, spacing):
    """The general construction on the triangle (0, 1, 2) with these local levels.

    Returns ``(refinement, slot_edge, slot_j)``: for each edge-point id of the lone refinement (offset 3),
    its local edge and its index along that edge from the edge's first corner.
    """
    tris = np.array([[0, 1, 2]], np.int32)
    edges = np.array([[0, 1], [0, 2], [1, 2]], np.int32)  # local edges 0, 2 (reversed), 1
    face_edges = np.array([[0, 2, 1]], np.int32)
    flipped = np.array([[False, False, True]])
    order = [0, 2, 1]
    levels = (np.asarray(outer_f, np.float64)[order], np.asarray(outer_n, np.int64)[order],
              np.array([inner_f], np.float64), np.array([inner_n], np.int64))
    ref = refine_general(tris, 3, edges, face_edges, flipped, levels, spacing)
    n0, n1, n2 = (int(x) for x in outer_n)
    k0, k2, k1 = np.arange(n0 - 1), np.arange(n2 - 1), np.arange(n1 - 1)
    slot_edge = np.concatenate([np.zeros(n0 - 1, np.int64), np.full(n2 - 1, 2), np.ones(n1 - 1, np.int64)])
    slot_j = np.concatenate([k0 + 1, n2 - (k2 + 1), k1 + 1])
    return ref, slot_edge, slot_j


def _template_edges(pat):
    """The edges of a class pattern in "edge slot" space.

    Columns of a face's edge slots: the segments of local edges 0, 1, 2 (``n_e`` each, counted from the local
    edge's first corner), then the pattern's interior edges. Returns ``(corner_cols (Mt, 3) column of the edge
    leaving each corner of each pattern triangle, interior_at (Ei,) one pattern corner (flat index into
    ``(Mt, 3)``) whose leaving edge is each interior edge)``.
    """
    n = pat.outer_n
    slot_edge, slot_j = pat.slot_edge, pat.slot_j
    n_slots = 3 + len(slot_edge) + len(pat.interior_bary)
    # position of every vertex slot along each local edge (-1: not on it); local edge e runs corner e -> e + 1
    pos = np.full((n_slots, 3), -1, np.int64)
    for c in range(3):
        pos[c, c] = 0
        pos[c, (c + 2) % 3] = n[(c + 2) % 3]
    pos[3 + np.arange(len(slot_edge)), slot_edge] = slot_j
    a = pat.triangles.astype(np.int64)
    b = np.roll(a, -1, axis=1)
    both = (pos[a] >= 0) & (pos[b] >= 0)  # (Mt, 3, 3): both ends on local edge e
    on_boundary = both.any(axis=2)
    e = both.argmax(axis=2)
    pa = np.take_along_axis(pos[a], e[..., None], axis=2)[..., 0]
    pb = np.take_along_axis(pos[b], e[..., None], axis=2)[..., 0]
    if np.any(on_boundary & (np.abs(pa - pb) != 1)):
        raise AssertionError("a pattern edge on a triangle side skips a point")
    cols = np.empty(a.shape, np.int64)
    offsets = np.concatenate(([0], np.cumsum(n)))
    cols[on_boundary] = offsets[e[on_boundary]] + np.minimum(pa, pb)[on_boundary]
    lo, hi = np.minimum(a, b)[~on_boundary], np.maximum(a, b)[~on_boundary]
    _, first, local = np.unique(lo * n_slots + hi, return_index=True, return_inverse=True)
    cols[~on_boundary] = offsets[3] + local.reshape(-1)
    return cols, np.flatnonzero(~on_boundary)[first]


def edge_segments(edges, edge_n, point_start, n_vertices):
    """The output edges along the input edges: every segment of every input edge, in edge order and canonical
    direction. Returns ``(seg_start (E,) int64 first segment of each input edge, ends (S, 2) int64 its output
    vertices)``."""
    seg_e, seg_k, seg_start = ragged(edge_n)
    ends = edges.astype(np.int64)

    def vertex_at(e, q):  # vertex at canonical position q along input edge e
        inner = n_vertices + point_start[e] + q - 1
        return np.where(q == 0, ends[e, 0], np.where(q == edge_n[e], ends[e, 1], inner))

    return seg_start, np.stack([vertex_at(seg_e, seg_k), vertex_at(seg_e, seg_k + 1)], axis=1)


def _output_edges(tris, n_vertices, edges, face_edges, flipped, edge_n, point_start, classes, triangles, tri_start):
    """Edges of the refined mesh and the edge leaving each output corner, from the class patterns.

    classes: per class ``(PatternClass, corner_cols, interior_at)`` (`_template_edges`). Returns ``(edges (K, 2)
    int32, corner_edges (M, 3) int32)``: the segments of every input edge (in edge order, canonical direction)
    then each face's interior edges.
    """
    seg_start, seg_ends = edge_segments(edges, edge_n, point_start, n_vertices)
    n_seg = len(seg_ends)
    face_interior = np.zeros(len(tris), np.int64)
    for cls, _, interior_at in classes:
        face_interior[cls.faces] = len(interior_at)
    interior_start = n_seg + np.cumsum(face_interior) - face_interior
    out_edges = np.empty((n_seg + int(face_interior.sum()), 2), np.int32)
    out_edges[:n_seg] = seg_ends
    corner_edges = np.empty(triangles.shape, np.int32)
    outer_n = edge_n[face_edges]
    for cls, cols, interior_at in classes:
        faces = cls.faces
        n = outer_n[faces[0]]
        slot_cols = np.empty((len(faces), int(n.sum()) + len(interior_at)), np.int32)
        start = 0
        for e in range(3):
            q = np.arange(int(n[e]))
            fe = face_edges[faces, e][:, None]
            canonical = np.where(flipped[faces, e][:, None], n[e] - 1 - q, q)
            slot_cols[:, start:start + n[e]] = seg_start[fe] + canonical
            start += int(n[e])
        ids = interior_start[faces][:, None] + np.arange(len(interior_at))
        slot_cols[:, start:] = ids
        if len(interior_at):  # an interior edge's ends: the corner it leaves and the next, in the output triangles
            corner = (3 * tri_start[faces])[:, None] + (interior_at - interior_at % 3)  # first corner of its triangle
            flat = triangles.reshape(-1)
            ends = np.stack([np.take(flat, corner + interior_at % 3), np.take(flat, corner + (interior_at + 1) % 3)],
                            axis=-1).astype(np.int32).reshape(-1, 2)
            if cls.consecutive:  # the faces' interior edges are one run
                out_edges[int(ids[0, 0]):int(ids[-1, -1]) + 1] = ends
            else:
                put_rows(out_edges, ids.ravel(), ends)
        scatter_rows(corner_edges, cls, tri_start, stamp(slot_cols, cols.ravel()).reshape(len(faces), -1, 3))
    return out_edges, corner_edges


@dataclass(frozen=True)
class PatternClass:
    """One refinement pattern and the faces it is stamped onto.

    A face's vertices are addressed by *slot*: its corners 0, 1, 2; then its edge points (``slot_edge`` and
    ``slot_j``: local edge ``e`` and index ``j`` counted from corner ``e``, ``outer_n[e]`` segments); then its
    interior points, in order. faces: (F,) int64 ascending; triangles: (Mt, 3) int32 slot of each corner of the
    pattern's triangles; slot_edge, slot_j: (S,) int64; interior_bary: (P, 3) float64; corner_bary: (Mt, 3, 3)
    float64; outer_n: (3,) int64.
    """

    faces: np.ndarray
    triangles: np.ndarray
    slot_edge: np.ndarray
    slot_j: np.ndarray
    interior_bary: np.ndarray
    corner_bary: np.ndarray
    outer_n: np.ndarray

    def edge_points(self, face_edges, flipped, point_start):
        """Where each face's edge slots sit among the refinement's edge points.

        face_edges, flipped: (T, 3) of the mesh; point_start: (E,) offset of each mesh edge's first point.
        Returns ``(index (F, S) int64 into the edge-point arrays, flip (F, S) bool: the local edge runs against
        the mesh edge's canonical direction)``.
        """
        flip = flipped[self.faces][:, self.slot_edge]
        canonical = np.where(flip, self.outer_n[self.slot_edge] - self.slot_j, self.slot_j)
        return point_start[face_edges[self.faces][:, self.slot_edge]] + canonical - 1, flip

    @property
    def consecutive(self):
        """True when the faces are one run ``faces[0] .. faces[-1]`` (their output rows form one block)."""
        return int(self.faces[-1]) - int(self.faces[0]) + 1 == len(self.faces)


def stamp(table, slots):
    """Per-face slot values gathered at pattern slots: ``table`` (F, ns, ...) , slots (k,) -> (F, k, ...).

    Each slot's row is moved as whole 64-bit (or 32-bit) words, in one `np.take` pass."""
    f, ns = table.shape[:2]
    item = table.dtype.itemsize * int(np.prod(table.shape[2:], dtype=np.int64))
    word = np.int64 if item % 8 == 0 else np.int32 if item % 4 == 0 else np.uint8
    width = item // np.dtype(word).itemsize
    words = np.ascontiguousarray(table).view(word).reshape(f, ns * width)
    index = slots if width == 1 else (np.asarray(slots, np.int64)[:, None] * width + np.arange(width)).ravel()
    return np.take(words, index, axis=1).view(table.dtype).reshape((f, len(slots)) + table.shape[2:])


def scatter_rows(out, cls, starts, block):
    """Write per-face blocks (F, k, ...) of class ``cls`` into ``out`` rows ``starts[face] ...``."""
    f, k = block.shape[:2]
    if cls.consecutive:
        lo = int(starts[cls.faces[0]])
        out[lo : lo + f * k] = block.reshape((f * k,) + out.shape[1:])
    else:
        out[(starts[cls.faces][:, None] + np.arange(k)).ravel()] = block.reshape((f * k,) + out.shape[1:])


def triangle_starts(classes, n_faces):
    """First output triangle of every face of a class-built refinement: (T,) int64 (faces in order, each
    face's triangles contiguous, as `refine_by_class` writes them)."""
    counts = np.zeros(n_faces, np.int64)
    for cls in classes:
        counts[cls.faces] = len(cls.triangles)
    return np.cumsum(counts) - counts


def slot_bary(cls):
    """Barycentric coordinates of every vertex slot of a class's pattern: (slots, 3) float64, taken from the
    pattern's corner barycentrics (so a slot's value equals what a per-corner evaluation would give)."""
    n_slots = 3 + len(cls.slot_edge) + len(cls.interior_bary)
    out = np.zeros((n_slots, 3))
    out[cls.triangles.ravel()] = cls.corner_bary.reshape(-1, 3)
    return out


def refine_by_class(tris, n_vertices, edges, face_edges, flipped, levels, classes, spacing):
    """Same contract as `kernels.tessellation.refine.refine`, built per pattern class. Returns a `Refinement`."""
    edge_f, edge_n, inner_f, inner_n = levels
    first, inverse = classes
    outer_n = edge_n[face_edges]
    outer_f = edge_f[face_edges]
    point_edge, point_start, edge_point_t = edge_points(edge_f, edge_n, spacing)
    interior_counts = count_interior(inner_n)
    interior_start = np.cumsum(interior_counts) - interior_counts
    interior_first = n_vertices + len(point_edge)
    tri_counts = outer_n.sum(axis=1) + 2 * interior_counts - 2
    tri_start = np.cumsum(tri_counts) - tri_counts
    n_out = int(tri_counts.sum())

    pattern_classes_ = []
    for f0, faces in zip(first, group_by_class(inverse, len(first)), strict=True):
        pat, slot_edge, slot_j = _lone_pattern(outer_f[f0], outer_n[f0], inner_f[f0], inner_n[f0], spacing)
        pattern_classes_.append(PatternClass(
            faces=faces, triangles=pat.triangles.astype(np.int32), slot_edge=slot_edge, slot_j=slot_j,
            interior_bary=pat.interior_bary, corner_bary=pat.corner_bary, outer_n=outer_n[f0].astype(np.int64)))
    pattern_classes_ = tuple(pattern_classes_)

    def triangles():
        out = None
        for cls in pattern_classes_:
            faces, n_edge_slots = cls.faces, len(cls.slot_edge)
            n_interior = int(interior_counts[faces[0]])
            table = np.empty((len(faces), 3 + n_edge_slots + n_interior), np.int32)  # vertex id of each slot
            table[:, :3] = tris[faces]
            if n_edge_slots:
                table[:, 3 : 3 + n_edge_slots] = n_vertices + cls.edge_points(face_edges, flipped, point_start)[0]
            table[:, 3 + n_edge_slots :] = (interior_first + interior_start[faces])[:, None] + np.arange(n_interior)
            stamped = stamp(table, cls.triangles.ravel())  # (F, Mt * 3)
            if len(faces) == len(tris):  # one class: the stamped block is the output
                return stamped.reshape(-1, 3)
            out = np.empty((n_out, 3), np.int32) if out is None else out
            scatter_rows(out, cls, tri_start, stamped.reshape(len(faces), -1, 3))
        return out

    def interior_bary():
        out = np.empty((int(interior_counts.sum()), 3))
        for cls in pattern_classes_:
            if len(cls.interior_bary):
                scatter_rows(out, cls, interior_start, np.broadcast_to(cls.interior_bary, (len(cls.faces),)
                                                                       + cls.interior_bary.shape))
        return out

    def corner_bary():
        out = np.empty((n_out, 3, 3))
        for cls in pattern_classes_:
            scatter_rows(out, cls, tri_start, np.broadcast_to(cls.corner_bary, (len(cls.faces),)
                                                              + cls.corner_bary.shape))
        return out

    def output_edges():
        per_class = [(cls, *_template_edges(cls)) for cls in pattern_classes_]
        return _output_edges(tris, n_vertices, edges, face_edges, flipped, edge_n, point_start, per_class,
                             ref.triangles, tri_start)

    n_faces = len(tris)
    ref = Refinement(
        n_corners=int(n_vertices), faces=tris, edges=edges,
        edge_point_edge=point_edge.astype(np.int32), edge_point_t=edge_point_t, spacing=spacing,
        edge_level=edge_f, edge_segments=edge_n, inner_level=inner_f, inner_segments=inner_n,
        interior_counts=interior_counts, n_triangles=n_out, face_edges=face_edges, flipped=flipped,
        arrays=LazyArrays(
            triangles=Lazy(triangles),
            triangle_face=Lazy(lambda: np.repeat(np.arange(n_faces, dtype=np.int32), tri_counts)),
            interior_face=Lazy(lambda: np.repeat(np.arange(n_faces, dtype=np.int32), interior_counts)),
            interior_bary=Lazy(interior_bary), corner_bary=Lazy(corner_bary), output_edges=Lazy(output_edges)),
        face_class=inverse, classes=pattern_classes_,
    )
    return ref

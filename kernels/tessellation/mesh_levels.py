"""A mesh's levels clamped and counted once (`MeshLevels`), carried with its edge table from the choice of levels
through the memory estimate to the refinement, so no step builds the edge table or clamps the levels again."""

from dataclasses import dataclass

import numpy as np

from ..common.errors import InvalidInputError
from ..common.topology import MeshTopology, mesh_topology
from .refine_general import face_levels, interior_counts


@dataclass(frozen=True)
class MeshLevels:
    """The levels a refinement is built at, on one mesh's topology.

    topology: `kernels.common.topology.MeshTopology`; edge_level (E,) float64 and edge_segments (E,) int64: each
    edge's clamped level and segment count; inner_level (T,) float64 and inner_segments (T,) int64: each face's;
    spacing: ``"EQUAL"`` or ``"FRACTIONAL_EVEN"`` (`kernels.common.partition`).
    """

    topology: MeshTopology
    edge_level: np.ndarray
    edge_segments: np.ndarray
    inner_level: np.ndarray
    inner_segments: np.ndarray
    spacing: str

    @property
    def levels(self):
        """``(edge_level, edge_segments, inner_level, inner_segments)``, as the refinement takes them."""
        return self.edge_level, self.edge_segments, self.inner_level, self.inner_segments

    def counts(self):
        """``(output vertices, output triangles)`` of the refinement, without building it."""
        topo = self.topology
        interior = interior_counts(self.inner_segments)
        boundary = self.edge_segments[topo.face_edges].sum(axis=1)
        n_vertices_out = topo.n_vertices + int((self.edge_segments - 1).sum()) + int(interior.sum())
        # Euler's formula for a triangulated disk: T = 2V - B - 2 with V = B + interior.
        return n_vertices_out, int((boundary + 2 * interior - 2).sum())

    def check_mesh(self, triangles, n_vertices):
        """Refuse a mesh these levels were not made for (another triangle or vertex count)."""
        if len(triangles) != len(self.topology.triangles) or n_vertices != self.topology.n_vertices:
            raise InvalidInputError(f"These levels are for a mesh of {len(self.topology.triangles)} triangles and "
                                    f"{self.topology.n_vertices} vertices, not {len(triangles)} and {n_vertices}")


def mesh_levels(topology, edge_levels, inner_levels=None, spacing="EQUAL"):
    """Clamp and count ``edge_levels`` (E,) and ``inner_levels`` (T,) or None (each face's largest edge level) on
    ``topology`` (a `MeshTopology`): a `MeshLevels`."""
    topo = topology
    levels = face_levels(topo.face_edges, len(topo.edges), edge_levels, inner_levels, spacing)
    return MeshLevels(topo, *levels, spacing)


def carried_levels(triangles, n_vertices, edge_levels, inner_levels=None, spacing="EQUAL"):
    """``edge_levels`` when it is a `MeshLevels` already (checked against the mesh), else the `MeshLevels` of these
    arrays: what `refine`, `estimate` and `tessellate` take either way."""
    if isinstance(edge_levels, MeshLevels):
        edge_levels.check_mesh(triangles, n_vertices)
        return edge_levels
    return mesh_levels(mesh_topology(triangles, n_vertices), edge_levels, inner_levels, spacing)

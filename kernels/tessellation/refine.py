"""Barycentric refinement patterns for whole triangle meshes, in the style of the hardware tessellator.

Every triangle is refined by the fixed-function triangle tessellator's construction (OpenGL 4 /
D3D11): its three edges are split into ``n0, n1, n2`` segments (one level per mesh edge), and the
interior is filled with concentric triangular rings driven by the inner level ``m``: ring ``k`` has
``m - 2k`` segments per side and the innermost ring is a point (``m`` even) or a triangle (``m`` odd).
When every outer level is 1 and the inner level is 1 the triangle is left alone; an inner level of 1
with a subdivided edge is raised to 2 (one centre vertex), as the hardware does. Adjacent rings are
joined by a zipper that merges their segments by parameter, so every triangle count equals the
hardware's (a triangle with uniform level ``n`` gives ``floor(3 n^2 / 2)`` triangles; see
`triangle_count`).

Output vertices are welded by construction, in three groups:

1. the input vertices, unchanged, at indices ``[0, V)``;
2. the points inside each mesh edge, generated once per edge in its canonical direction (lower vertex
   index first), so both triangles of a shared edge use the very same vertices;
3. the points inside each triangle, described by barycentric coordinates.

The topology does not depend on positions. A `Refinement` records where each output vertex comes
from, so any surface (linear here; PN and Phong on top) and any attribute can be evaluated on it.
Quads and n-gons must be triangulated first (the Blender bridge uses Blender's loop triangles).

Local conventions: local edge ``e`` of a triangle runs from corner ``e`` to corner ``(e + 1) % 3``. In
OpenGL terms, local edge 0 (v0-v1) is ``gl_TessLevelOuter[2]``, edge 1 (v1-v2) is ``[0]`` and edge 2
(v2-v0) is ``[1]``.
"""

import numpy as np

from . import refine_templates
from .mesh_levels import carried_levels
from .refine_split import refine_split


def refinement_counts(triangles, n_vertices, edge_levels, inner_levels=None, spacing="EQUAL"):
    """Output sizes without building the refinement (for memory budgets and progress).

    Returns ``(n_out_vertices, n_out_triangles)``. Arguments as in `refine`.
    """
    return carried_levels(triangles, n_vertices, edge_levels, inner_levels, spacing).counts()


def triangle_count(outer, inner):
    """Triangles the pattern has for one triangle with OpenGL-ordered outer levels and an inner level.

    outer: (3,) ints ``(OL0, OL1, OL2)``; inner: int. Equal spacing. Returns int.
    """
    return refinement_counts(*single_triangle_levels(outer, inner))[1]


def single_triangle_levels(outer, inner):
    """Arguments for `refine` for the triangle ``(0, 1, 2)`` with OpenGL-ordered levels.

    Returns ``(triangles, n_vertices, edge_levels, inner_levels)``; edges are ordered (0,1), (0,2), (1,2).
    """
    ol0, ol1, ol2 = (float(x) for x in outer)
    # edges sorted: (0,1) is v0-v1 -> OL2; (0,2) is v2-v0 -> OL1; (1,2) is v1-v2 -> OL0.
    return np.array([[0, 1, 2]], np.int32), 3, np.array([ol2, ol1, ol0]), np.array([float(inner)])


def refine(triangles, n_vertices, edge_levels, inner_levels=None, spacing="EQUAL"):
    """Refine a triangle mesh with one level per edge and one inner level per triangle.

    triangles: (T, 3) int, counter-clockwise; n_vertices: int, V;
    edge_levels: (E,) float, one level per edge of `kernels.common.topology.triangle_edges` (sorted ``(lo, hi)``), or
    a `kernels.tessellation.mesh_levels.MeshLevels` carried from an earlier step (then it holds the inner levels and
    the spacing, and the edge table is not built again);
    inner_levels: (T,) float or None (then the largest of the triangle's three edge levels);
    spacing: ``"EQUAL"`` or ``"FRACTIONAL_EVEN"`` (see `kernels.common.partition`).
    Returns a `Refinement`. Shared edges give shared vertices, so a closed manifold input gives a closed
    manifold output.
    """
    carried = carried_levels(triangles, n_vertices, edge_levels, inner_levels, spacing)
    topo, levels, spacing = carried.topology, carried.levels, carried.spacing
    edge_f, edge_n, inner_f, inner_n = levels
    tris, edges, face_edges, flipped = topo.triangles, topo.edges, topo.face_edges, topo.flipped
    classes = refine_templates.pattern_classes(edge_f[face_edges], edge_n[face_edges], inner_f, inner_n, spacing)
    if refine_templates.worth_it(classes, len(tris)):
        return refine_templates.refine_by_class(tris, topo.n_vertices, edges, face_edges, flipped, levels, classes,
                                                spacing)
    return refine_split(tris, topo.n_vertices, edges, face_edges, flipped, levels, spacing)

"""Data for evaluating PN / Phong / linear tessellation on the GPU, without tessellation hardware.

Boubekeur & Schlick, "Generic Mesh Refinement on GPU" (GPU Gems 3 ch. 5): one refinement *pattern* per level
class, drawn instanced, one instance per input triangle; the vertex shader reads its triangle's control data
from a texture and places the pattern vertex on the curved surface. This module builds, in numpy:

- `pattern`: the pattern of a class ``(n0, n1, n2, m)`` (segment counts of local edges 0, 1, 2 and the inner
  segment count): its vertex *codes* and triangles, taken from `kernels.tessellation.refine` on a single triangle, so
  the topology is the CPU refinement's. A code is ``(kind, a, b, c)``: kind 0 corner ``a``; kind 1 point ``b`` of
  local edge ``a`` (counted from corner ``a``); kind 2 interior point ``c`` of side ``b`` of ring ``a``.
- `control_rows`: per input triangle, `CONTROL_ROWS` RGBA32F texels of control data (below), uploaded once per
  mesh; `instance_rows`: per drawn triangle its levels and id, uploaded when the levels change.
- `vertex_codes`: for every vertex of a CPU `Refinement`, one owning triangle and its code (the compute path
  evaluates each welded vertex once, with the same GLSL function as the preview).

Control texels of triangle ``t`` (rows ``CONTROL_ROWS * t ...``): 0-2 corner position and Phong shape factor;
3-5 geometry normal (one per vertex: watertight) and whether the local edge runs against the canonical
``lo -> hi`` direction; 6-8 shading normal (split corner normals where the mesh has them); 9-10 corner UVs;
11-13 corner tangent and bitangent sign (tangent-space displacement).
Edge points are evaluated from the canonical direction of their edge,
from data both triangles hold bit for bit, so shared edges have the same vertices.
"""

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..common.partition import clamp_levels
from ..common.topology import ragged, triangle_edges
from .refine import refine, single_triangle_levels
from .refine_general import face_levels

CONTROL_ROWS = 14
KIND_CORNER, KIND_EDGE, KIND_INTERIOR = 0, 1, 2


def interior_codes(m):
    """Codes (P, 4) float32 of the interior points of a triangle with inner segment count ``m``, in the order
    `kernels.tessellation.refine` numbers them (ring by ring, ring corner by ring corner)."""
    rows = []
    for k in range(1, m // 2 + 1):
        side = m - 2 * k
        if side == 0:
            rows.append((KIND_INTERIOR, k, 0, 0))
            continue
        rows.extend((KIND_INTERIOR, k, pos // side, pos % side) for pos in range(3 * side))
    return np.array(rows, np.float32).reshape(-1, 4)


@lru_cache(maxsize=4096)
def pattern(n0, n1, n2, m):
    """Pattern of class ``(n0, n1, n2, m)``: ``(codes (P, 4) float32, triangles (Q, 3) int32)``, counter-clockwise
    like the input triangle, vertices numbered as `kernels.tessellation.refine` numbers them for a lone triangle.
    Cached: the arrays are read-only."""
    tris, n_vertices, edge_levels, _ = single_triangle_levels((n1, n2, n0), m)  # OpenGL order: OL0 = v1-v2
    ref = refine(tris, n_vertices, edge_levels, np.array([float(m)]), "EQUAL")
    codes = [(KIND_CORNER, c, 0, 0) for c in range(3)]
    local = {(0, 1): (0, False), (1, 2): (1, False), (0, 2): (2, True)}  # canonical edge -> local edge, flipped
    counts = (n0, n1, n2)
    for edge in range(len(ref.edges)):
        e, flip = local[tuple(int(v) for v in ref.edges[edge])]
        n = counts[e]
        codes.extend((KIND_EDGE, e, n - j if flip else j, 0) for j in range(1, n))
    inner = int(ref.inner_segments[0])
    codes = np.concatenate([np.array(codes, np.float32).reshape(-1, 4), interior_codes(inner)])
    if len(codes) != ref.n_vertices:
        raise AssertionError(f"pattern {(n0, n1, n2, m)}: {len(codes)} codes for {ref.n_vertices} vertices")
    tris = ref.triangles.astype(np.int32)
    codes.setflags(write=False)
    tris.setflags(write=False)
    return codes, tris


@dataclass
class PatchClasses:
    """Input triangles grouped by pattern class: ``{(n0, n1, n2, m): (T_k,) int64 triangle ids}``."""

    classes: dict
    counts: np.ndarray  # (T, 4) int64 segment counts (n0, n1, n2, m) per triangle
    levels: np.ndarray  # (T, 4) float64 clamped levels (f0, f1, f2, f_inner)


def patch_classes(triangles, n_vertices, edge_levels, inner_levels=None, spacing="EQUAL"):
    """Segment counts and clamped levels per triangle (local edge order), grouped by class.

    Same rules as `kernels.tessellation.refine.refine` (clamping, the inner level raised to 2 next to a split edge).
    """
    tris = np.asarray(triangles)
    edges, face_edges, _ = triangle_edges(tris)
    edge_f, edge_n, inner_f, inner_n = face_levels(face_edges, len(edges), edge_levels, inner_levels, spacing)
    counts = np.concatenate([edge_n[face_edges], inner_n[:, None]], axis=1).astype(np.int64)
    levels = np.concatenate([edge_f[face_edges], clamp_levels(inner_f, spacing)[:, None]], axis=1)
    key = ((counts[:, 0] * 65 + counts[:, 1]) * 65 + counts[:, 2]) * 65 + counts[:, 3]
    uniq, inverse = np.unique(key, return_inverse=True)
    order = np.argsort(inverse, kind="stable")
    bounds = np.searchsorted(inverse[order], np.arange(len(uniq) + 1))
    classes = {}
    for i in range(len(uniq)):
        ids = order[bounds[i]:bounds[i + 1]]
        classes[tuple(int(c) for c in counts[ids[0]])] = ids
    return PatchClasses(classes, counts, levels)


def control_rows(inputs, alpha=0.75, uvs=None, tangents=None):
    """Control texels of every triangle, independent of the levels: (T, CONTROL_ROWS, 4) float32.

    inputs: a `kernels.tessellation.tessellate.SurfaceInputs`; alpha: the constant shape factor where
    ``inputs.alpha`` is None; uvs: (T, 3, 2) per corner, or None; tangents: (T, 3, 4) per corner (xyz, bitangent
    sign), or None.
    """
    tris = np.asarray(inputs.mesh.triangles, np.int64)
    _, _, flipped = triangle_edges(tris)
    rows = np.zeros((len(tris), CONTROL_ROWS, 4), np.float32)
    rows[:, 0:3, :3] = inputs.positions[tris]
    rows[:, 0:3, 3] = float(alpha) if inputs.alpha is None else inputs.alpha[tris]
    rows[:, 3:6, :3] = np.asarray(inputs.vertex_normals, np.float64)[tris]
    rows[:, 3:6, 3] = flipped
    rows[:, 6:9, :3] = inputs.shading_normals()
    if uvs is not None:
        uv = np.asarray(uvs, np.float32)
        rows[:, 9, :2], rows[:, 9, 2:], rows[:, 10, :2] = uv[:, 0], uv[:, 1], uv[:, 2]
    if tangents is not None:
        rows[:, 11:14] = tangents
    return rows


def instance_rows(classes, triangles):
    """Per-instance texels of some triangles of one class: (k, 2, 4) float32, (f0, f1, f2, f_inner) then
    (triangle id, 0, 0, 0). Ids are exact below 2^24 triangles."""
    rows = np.zeros((len(triangles), 2, 4), np.float32)
    rows[:, 0] = classes.levels[triangles]
    rows[:, 1, 0] = triangles
    return rows


def vertex_rows(ref, classes):
    """Per-vertex texels for evaluating every vertex of ``ref`` once (the compute path): (N, 4, 4) float32,
    code, owner's levels, owner's segment counts, (owner, 0, 0, 0)."""
    owner, codes = vertex_codes(ref, classes)
    rows = np.zeros((len(owner), 4, 4), np.float32)
    rows[:, 0], rows[:, 1], rows[:, 2] = codes, classes.levels[owner], classes.counts[owner]
    rows[:, 3, 0] = owner
    return rows


def vertex_codes(ref, classes):
    """One owning triangle and code per vertex of ``ref`` (a `Refinement` of the same mesh and levels).

    Returns ``(owner (N,) int64, codes (N, 4) float32)`` in ``ref``'s vertex order.
    """
    tris = np.asarray(ref.faces, np.int64)
    _, face_edges, flipped = triangle_edges(tris)
    n_corners, n_edge_points = ref.n_corners, len(ref.edge_point_edge)
    owner = np.empty(ref.n_vertices, np.int64)
    codes = np.zeros((ref.n_vertices, 4), np.float32)
    # corners: any triangle that uses the vertex
    face_of, corner_of = np.repeat(np.arange(len(tris)), 3), np.tile(np.arange(3), len(tris))
    v = tris.ravel()
    owner[v], codes[v, 1] = face_of, corner_of
    codes[:n_corners, 0] = KIND_CORNER
    # edge points: a triangle holding the edge, and the point's index along that triangle's local edge
    edge_face = np.empty(len(ref.edges), np.int64)
    edge_local = np.empty(len(ref.edges), np.int64)
    edge_face[face_edges.ravel()], edge_local[face_edges.ravel()] = face_of, corner_of
    e = ref.edge_point_edge.astype(np.int64)
    _, jc, _ = ragged(ref.edge_segments - 1)
    jc = jc + 1
    f, le = edge_face[e], edge_local[e]
    n = ref.edge_segments[e]
    ids = np.arange(n_corners, n_corners + n_edge_points)
    owner[ids] = f
    codes[ids, 0], codes[ids, 1] = KIND_EDGE, le
    codes[ids, 2] = np.where(flipped[f, le], n - jc, jc)
    # interior points: their face, ring by ring
    first = n_corners + n_edge_points
    face, _, _ = ragged(ref.interior_counts)
    owner[first:] = face
    for m in np.unique(ref.inner_segments):
        faces = np.flatnonzero((ref.inner_segments == m) & (ref.interior_counts > 0))
        if not len(faces):
            continue
        local = interior_codes(int(m))
        starts = first + np.cumsum(ref.interior_counts) - ref.interior_counts
        rows = (starts[faces][:, None] + np.arange(len(local))).ravel()
        codes[rows] = np.tile(local, (len(faces), 1))
    return owner, codes


def code_parameters(codes, levels, counts, flipped, spacing="EQUAL"):
    """What the shaders compute from a code (the numpy reference of ``patch_eval.glsl``).

    codes: (N, 4); levels, counts: (N, 4) the owning triangle's rows 9 and 10; flipped: (N, 3) bool its
    local edges' directions. Returns ``(bary (N, 3) float64, edge_t (N,) float64)``: barycentrics in the
    owning triangle, and for edge points the parameter along the edge's canonical ``lo -> hi`` direction.
    """
    from ..common.partition import point_params

    codes = np.asarray(codes)
    kind, a, b, c = (codes[:, i].astype(np.int64) for i in range(4))
    rows = np.arange(len(codes))
    bary = np.zeros((len(codes), 3))
    edge_t = np.zeros(len(codes))
    corner = kind == KIND_CORNER
    bary[rows[corner], a[corner]] = 1.0
    edge = np.flatnonzero(kind == KIND_EDGE)
    e = a[edge]
    n = counts[edge, e]
    flip = flipped[edge, e]
    jc = np.where(flip, n - b[edge], b[edge])
    t = point_params(levels[edge, e], n, jc, spacing)
    edge_t[edge] = t
    t_local = np.where(flip, 1.0 - t, t)
    bary[edge, e], bary[edge, (e + 1) % 3] = 1.0 - t_local, t_local
    q = np.flatnonzero(kind == KIND_INTERIOR)
    k, cq, j = a[q], b[q], c[q]
    m = counts[q, 3]
    f = levels[q, 3]
    side = np.maximum(m - 2 * k, 1)
    p_ring, p_point = point_params(f, m, k, spacing), point_params(f, m, k + j, spacing)
    off = (2.0 / 3.0) * p_ring
    span = 1.0 - 2.0 * p_ring
    with np.errstate(divide="ignore", invalid="ignore"):
        phi = np.where(span > 0, (p_point - p_ring) / span, j / side)
    b_next = off + phi * (1.0 - 3.0 * off)
    bary[q, cq], bary[q, (cq + 1) % 3], bary[q, (cq + 2) % 3] = 1.0 - b_next - off, b_next, off
    bary[q[m - 2 * k == 0]] = 1.0 / 3.0
    return bary, edge_t

"""The general refinement: every face's rings and zipper at once, for any mix of levels (see `refine`).

`face_levels` clamps and rounds the levels, `interior_counts` counts a face's interior points, and
`refine_general` builds the `Refinement`; `refine_templates` runs the same construction once per pattern class.
"""

import numpy as np

from ..common.errors import InvalidInputError
from ..common.partition import clamp_levels, point_params, segment_counts
from ..common.topology import ragged
from .refinement import Lazy, LazyArrays, Refinement


def interior_counts(m):
    """Interior vertices of a triangle with inner segment count ``m``: (T,) int64 -> (T,) int64."""
    rings = m // 2
    return 3 * (rings * m - rings * (rings + 1)) + (m % 2 == 0)


def face_levels(face_edges, n_edges, edge_levels, inner_levels, spacing):
    """Clamp and round levels. Returns ``(edge_f, edge_n, inner_f, inner_n)``, (E,) and (T,) each."""
    edge_levels = np.asarray(edge_levels, dtype=np.float64)
    if edge_levels.shape != (n_edges,):
        raise InvalidInputError(f"edge_levels must have shape ({n_edges},), one per edge; got {edge_levels.shape}")
    edge_f = clamp_levels(edge_levels, spacing)
    edge_n = segment_counts(edge_f, spacing).astype(np.int64)
    if inner_levels is None:
        inner_f = edge_f[face_edges].max(axis=1)
    else:
        inner_levels = np.asarray(inner_levels, dtype=np.float64)
        if inner_levels.shape != (len(face_edges),):
            raise InvalidInputError(
                f"inner_levels must have shape ({len(face_edges)},), one per triangle; got {inner_levels.shape}"
            )
        inner_f = clamp_levels(inner_levels, spacing)
    inner_n = segment_counts(inner_f, spacing).astype(np.int64)
    # The hardware rule: inner level 1 is treated as 1 + epsilon when any outer level is above 1.
    split = (edge_n[face_edges] > 1).any(axis=1)
    inner_n = np.where(split & (inner_n < 2), 2, inner_n)
    return edge_f, edge_n, inner_f, inner_n


def edge_points(edge_f, edge_n, spacing):
    """The points inside every mesh edge, in edge order and canonical direction: ``(point_edge (Ne,) int64 edge of
    each point, point_start (E,) int64 each edge's first point, edge_point_t (Ne,) float64 parameter from the
    edge's lower vertex)``."""
    point_edge, point_local, point_start = ragged(edge_n - 1)
    return point_edge, point_start, point_params(edge_f[point_edge], edge_n[point_edge], point_local + 1, spacing)


def refine_general(tris, n_vertices, edges, face_edges, flipped, levels, spacing):
    """The vectorised construction for any mix of levels (every face's rings and zipper at once)."""
    edge_f, edge_n, inner_f, inner_n = levels
    outer_n = edge_n[face_edges]  # (T, 3) segments of each local edge

    # Edge points, once per edge, in canonical direction: edge e owns ids [edge_first[e], + n_e - 1).
    point_edge, point_start, edge_point_t = edge_points(edge_f, edge_n, spacing)
    edge_first = n_vertices + point_start
    interior_first = n_vertices + len(point_edge)

    # Rings: ring 0 is the outer boundary loop, rings 1..m//2 are interior loops.
    ring_face, ring_k, _ = ragged(inner_n // 2 + 1)
    ring_m = inner_n[ring_face]
    side = ring_m - 2 * ring_k  # segments per side of an interior ring (0: a point)
    boundary = outer_n.sum(axis=1)[ring_face]
    n_loop_vertices = np.where(ring_k == 0, boundary, np.where(side >= 1, 3 * side, 1))
    n_segments = np.where(ring_k == 0, boundary, 3 * side)

    vertex_id, vertex_bary, vertex_face, interior, vertex_start = _ring_vertices(
        tris, face_edges, flipped, outer_n, edge_first, edge_point_t, n_vertices,
        ring_face, ring_k, n_loop_vertices, inner_f, inner_n, interior_first, spacing,
    )
    tri_rv = _zip_rings(ring_face, ring_k, ring_m, outer_n, side, n_loop_vertices, n_segments, vertex_start)

    return Refinement(
        n_corners=int(n_vertices),
        faces=tris,
        edges=edges,
        edge_point_edge=point_edge.astype(np.int32),
        edge_point_t=edge_point_t,
        spacing=spacing,
        edge_level=edge_f,
        edge_segments=edge_n,
        inner_level=inner_f,
        inner_segments=inner_n,
        interior_counts=interior_counts(inner_n),
        n_triangles=len(tri_rv),
        face_edges=face_edges,
        flipped=flipped,
        arrays=LazyArrays(
            triangles=Lazy.of(vertex_id[tri_rv].astype(np.int32)),
            triangle_face=Lazy.of(vertex_face[tri_rv[:, 0]].astype(np.int32)),
            interior_face=Lazy.of(vertex_face[interior].astype(np.int32)),
            interior_bary=Lazy.of(vertex_bary[interior]), corner_bary=Lazy(lambda: vertex_bary[tri_rv]),
            corner_slots=Lazy.of((vertex_face, vertex_bary, tri_rv))),
    )


def local_edge(position, outer_n):
    """Which local edge a boundary-loop position lies on and its index along that edge.

    position: (k,) int in ``[0, n0 + n1 + n2)``; outer_n: (k, 3) int. Returns ``(edge, index)``, (k,) each.
    """
    first = outer_n[:, 0]
    second = first + outer_n[:, 1]
    edge = (position >= first).astype(np.int64) + (position >= second)
    start = np.where(edge == 0, 0, np.where(edge == 1, first, second))
    return edge, position - start


def _ring_vertices(tris, face_edges, flipped, outer_n, edge_first, edge_point_t, n_vertices,
                   ring_face, ring_k, n_loop_vertices, inner_f, inner_n, interior_first, spacing):
    """Every loop vertex of every ring: output id, barycentric coordinates in its face, face.

    Returns ``(ids (N,) int64, bary (N, 3) float64, face (N,) int64, interior (N,) bool,
    ring_start (R,) int64)``, loop order within each ring, rings in order.
    """
    ring, pos, ring_start = ragged(n_loop_vertices)
    face = ring_face[ring]
    k = ring_k[ring]
    ids = np.empty(len(ring), dtype=np.int64)
    bary = np.zeros((len(ring), 3), dtype=np.float64)
    o = np.flatnonzero(k == 0)
    ids[o], bary[o] = boundary_vertices(tris, face_edges, flipped, outer_n, edge_first, edge_point_t, n_vertices,
                                        face[o], pos[o])
    # Interior rings: numbered consecutively after the edge points, in table order.
    q = np.flatnonzero(k >= 1)
    ids[q] = interior_first + np.arange(len(q))
    bary[q] = interior_bary(k[q], pos[q], inner_f[face[q]], inner_n[face[q]], spacing)
    return ids, bary, face, k >= 1, ring_start


def boundary_vertices(tris, face_edges, flipped, outer_n, edge_first, edge_point_t, n_vertices, face, pos):
    """Output id and barycentrics of boundary-loop positions ``pos`` (k,) of faces ``face`` (k,): corners and edge
    points, seen from each face's orientation of its edges. Returns ``(ids (k,) int64, bary (k, 3) float64)``."""
    e, j = local_edge(pos, outer_n[face])
    n_e = outer_n[face, e]
    is_corner = j == 0
    edge = face_edges[face, e]
    flip = flipped[face, e]
    canonical = np.where(flip, n_e - j, j)
    point = np.where(is_corner, 0, edge_first[edge] + canonical - 1)
    ids = np.where(is_corner, tris[face, e], point).astype(np.int64)
    # An edge point weighs the edge's canonical ends (1 - t, t) whichever way the face runs, so the two faces
    # of an edge interpolate corner attributes with the same weights (bit-identical where they agree at the ends).
    t = np.zeros(len(face))
    t[~is_corner] = edge_point_t[point[~is_corner] - n_vertices]
    w_lo, w_hi = 1.0 - t, t  # weights of the edge's lower and higher vertex
    bary = np.zeros((len(face), 3), dtype=np.float64)
    rows = np.arange(len(face))
    bary[rows, e] = np.where(is_corner, 1.0, np.where(flip, w_hi, w_lo))
    bary[rows, (e + 1) % 3] = np.where(is_corner, 0.0, np.where(flip, w_lo, w_hi))
    return ids, bary


def interior_bary(k, pos, inner_f, inner_n, spacing):
    """Barycentrics of interior-ring vertices: ring ``k`` >= 1 (q,), loop position ``pos`` (q,), of faces with
    clamped inner level ``inner_f`` (q,) and inner segment count ``inner_n`` (q,). Returns (q, 3) float64."""
    j = pos % np.maximum(inner_n - 2 * k, 1)
    return ring_bary(k, pos, inner_n, point_params(inner_f, inner_n, k, spacing),
                     point_params(inner_f, inner_n, k + j, spacing))


def ring_bary(k, pos, inner_n, p_ring, p_point):
    """`interior_bary` from the inner partition's parameters at the ring (``p_ring``: point ``k``) and at the vertex
    (``p_point``: point ``k + j``, j its index along its side), (q,) each. Returns (q, 3) float64."""
    side = inner_n - 2 * k
    c, j = pos // np.maximum(side, 1), pos % np.maximum(side, 1)
    own, b_next, off = side_weights(p_ring, p_point, j, side)
    bary = np.empty((len(k), 3), dtype=np.float64)
    for col in range(3):  # column c gets own, c + 1 b_next, c + 2 off
        bary[:, col] = np.where(c == col, own, np.where((c + 1) % 3 == col, b_next, off))
    return bary


def side_weights(p_ring, p_point, j, side):
    """The three barycentric weights of point ``j`` on a side of an interior ring, from that side's corner on
    (``own``), toward the next corner (``b_next``) and of the third corner (``off``); the centre point (``side``
    0) gets 1/3 each. All arguments of one shape; returns three float64 arrays of it."""
    safe_side = np.maximum(side, 1)
    off = (2.0 / 3.0) * p_ring  # ring corner c is (1 - 2 off) e_c + off (e_{c+1} + e_{c+2})
    span = 1.0 - 2.0 * p_ring
    with np.errstate(divide="ignore", invalid="ignore"):
        phi = np.where(span > 0, (p_point - p_ring) / span, j / safe_side)
    b_next = off + phi * (1.0 - 3.0 * off)
    own = 1.0 - b_next - off
    centre = side == 0
    if np.any(centre):
        own, b_next, off = (np.where(centre, 1.0 / 3.0, w) for w in (own, b_next, off))
    return own, b_next, off


def _segment_keys(ring_face, ring_k, outer_n, side, n_segments):
    """Parameter in [0, 3) of each ring segment's midpoint, ring corners at 0, 1, 2.

    Returns ``(ring (S,) int64, index (S,) int64, key (S,) float64, start (R,) int64)``.
    """
    ring, pos, start = ragged(n_segments)
    key = np.empty(len(ring), dtype=np.float64)
    outer = ring_k[ring] == 0
    o = np.flatnonzero(outer)
    n_o = outer_n[ring_face[ring[o]]]
    e, j = local_edge(pos[o], n_o)
    key[o] = e + (j + 0.5) / n_o[np.arange(len(o)), e]
    q = np.flatnonzero(~outer)
    s = side[ring[q]]
    key[q] = pos[q] // s + (pos[q] % s + 0.5) / s
    return ring, pos, key, start


def _zip_rings(ring_face, ring_k, ring_m, outer_n, side, n_loop_vertices, n_segments, vertex_start):
    """Triangulate between consecutive rings of each face (and the odd innermost triangle).

    Each segment of the outer ring of an annulus gets the inner vertex reached by the merge walk at
    its midpoint, and vice versa; ties go to the outer segment first. Returns (M, 3) int64 indices into
    the ring-vertex table, grouped by face.
    """
    rings_per_face = ring_m // 2
    has_inner = ring_k < rings_per_face
    is_inner = ring_k >= 1
    centre = (ring_k == rings_per_face) & (ring_m % 2 == 1)
    n_out = np.where(has_inner, n_segments, 0)
    n_in = np.where(is_inner, n_segments, 0)
    counts = n_out + n_in + centre
    tri_start = np.cumsum(counts) - counts
    tri_rv = np.empty((int(counts.sum()), 3), dtype=np.int64)

    seg_ring, seg_pos, key, seg_start = _segment_keys(ring_face, ring_k, outer_n, side, n_segments)
    walk = seg_ring * 4.0 + key  # sorted: rings ascending, keys ascending within a ring

    a = np.flatnonzero(has_inner[seg_ring])  # outer segments of an annulus
    r, i = seg_ring[a], seg_pos[a]
    inner_pos = np.searchsorted(walk, (r + 1) * 4.0 + key[a], side="left") - seg_start[r + 1]
    rows = tri_start[r] + i
    tri_rv[rows, 0] = vertex_start[r] + i
    tri_rv[rows, 1] = vertex_start[r] + (i + 1) % n_loop_vertices[r]
    tri_rv[rows, 2] = vertex_start[r + 1] + inner_pos % n_loop_vertices[r + 1]

    b = np.flatnonzero(is_inner[seg_ring])  # inner segments of an annulus
    r, j = seg_ring[b], seg_pos[b]
    outer_pos = np.searchsorted(walk, (r - 1) * 4.0 + key[b], side="right") - seg_start[r - 1]
    rows = tri_start[r] + n_out[r] + j
    tri_rv[rows, 0] = vertex_start[r] + (j + 1) % n_loop_vertices[r]
    tri_rv[rows, 1] = vertex_start[r] + j
    tri_rv[rows, 2] = vertex_start[r - 1] + outer_pos % n_loop_vertices[r - 1]

    c = np.flatnonzero(centre)
    rows = tri_start[c] + n_out[c] + n_in[c]
    tri_rv[rows] = vertex_start[c][:, None] + np.arange(3)
    return tri_rv

"""The welded mesh of patches at their levels (`tessellate_patches`): shared sides' points evaluated once, inner
grids by tensor contraction, strips zipping them, collapsed sides merged; and its size before it is made
(`estimate`)."""

from dataclasses import dataclass

import numpy as np

from ...common.budget import Estimate
from ...common.curves.rational_bezier import (
    bernstein,
    bernstein_derivative,
    cartesian,
)
from ...common.quad_pattern import pattern
from .nets import (
    PatchEdges,
    _contract_u,
    _contract_u_basis,
    _contract_v,
    _contract_v_basis,
    _plane_points,
    _point_and_normal,
    check_patches,
    inner_pairs,
    patch_edges,
)
from .pattern_uv import _pattern_counts, _pattern_uv, _pole_corners, _spaced_pattern_uv, _spaced_template


@dataclass
class PatchMesh:
    """positions (V, 3) float32; triangles (T, 3) int32; uv (V, 2) float32 and patch (V,) int64: where each vertex
    was evaluated (a shared vertex: its first patch); triangle_patch (T,) int64 and corner_uv (T, 3, 2) float32:
    each triangle's patch and its corners' (u, v) in it; normals (V, 3) float32: the surface's unit normal at each
    vertex. Oriented as Blender orients a NURBS surface's faces (its primitives face out): the normal along
    dS/dv x dS/du, the triangles clockwise in (u, v) (counter-clockwise seen from the normal's side)."""

    positions: np.ndarray
    triangles: np.ndarray
    uv: np.ndarray
    patch: np.ndarray
    triangle_patch: np.ndarray
    corner_uv: np.ndarray
    normals: np.ndarray = None

@dataclass
class SurfaceTessellation:
    """What `tessellate_surface` made: mesh (`PatchMesh`); edge_levels (E,) and inner_levels (P, 2) int64; edges
    (`PatchEdges`); deviation (P,) float64: the largest distance measured between each patch's triangles and the
    surface (NaN when the tolerance was not asked for); unmet (K,) int64: the patches still over the tolerance at Max
    Level. With the tolerance a patch may have been split into parts (`kernels.surfaces.patch_split`): then the mesh,
    the levels, the deviation and unmet are the parts', parent (P',) int64 is each part's patch and box (P', 2, 2)
    its ((u0, u1), (v0, v1)) there."""

    mesh: PatchMesh
    edge_levels: np.ndarray
    inner_levels: np.ndarray
    edges: PatchEdges
    deviation: np.ndarray
    unmet: np.ndarray
    parent: np.ndarray = None
    box: np.ndarray = None

    def patch_uv(self, outer=None):
        """Each triangle's corners' (u, v) in its patch (not its part): (T, 3, 2) float64. outer (P, 2, 2): each
        patch's ((u0, u1), (v0, v1)) in something larger (its spline: `kernels.common.curves.nurbs.PatchSet.box`): the
        corners' (u, v) there instead, (T, 3, 2) float32, each part's two boxes composed first."""
        if outer is None:
            b = self.box[self.mesh.triangle_patch][:, None]
            return b[..., 0] + self.mesh.corner_uv.astype(np.float64) * (b[..., 1] - b[..., 0])
        lo, size = self.box[:, :, 0], self.box[:, :, 1] - self.box[:, :, 0]
        o = np.asarray(outer, np.float64)[self.parent]
        o_lo, o_size = o[:, :, 0], o[:, :, 1] - o[:, :, 0]
        lo, size = o_lo + lo * o_size, size * o_size  # (P', 2): one affine map a part
        tp = self.mesh.triangle_patch
        return lo[tp].astype(np.float32)[:, None] + self.mesh.corner_uv * size[tp].astype(np.float32)[:, None]

def estimate(edge_levels, inner_levels):
    """The mesh's size at these levels, before it is made: an `Estimate` (peak bytes: the arrays being built,
    float64, and the result)."""
    n = np.maximum(np.asarray(inner_levels, np.int64), 2)
    n = np.stack([n, n], 1) if n.ndim == 1 else n
    vertices = int(4 * len(n) + (np.asarray(edge_levels, np.int64) - 1).sum() + ((n - 1).prod(axis=1)).sum())
    triangles = int((2 * n.prod(axis=1)).sum())
    return Estimate(vertices, triangles, vertices * 200 + triangles * 160)

def tessellate_patches(control, edge_levels, inner_levels, edges=None, spacing=None):
    """The welded triangle mesh of the patches at these levels: a `PatchMesh`; equal steps, or steps where
    ``spacing`` (a `Spacing`) puts them (then each strip between a side and the inner grid is zipped by the points'
    parameters)."""
    h = check_patches(control)
    edges = edges if edges is not None and edges.collapsed is not None else patch_edges(h)
    n_p = len(h)
    el = np.asarray(edge_levels, np.int64)
    corners, side = _side_points(h, edges, el, spacing)
    side_counts = el[edges.edge]  # (P, 4)
    n_in = _pattern_counts(inner_pairs(inner_levels, n_p), side_counts)  # (P, 2): steps along u and along v
    inner = _inner_points(h, n_in, spacing)
    corner_uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float64)
    n_c = 4 * n_p
    positions = np.concatenate([corners.reshape(-1, 3), side.points, inner.points])
    uv = np.concatenate([np.tile(corner_uv, (n_p, 1)), side.uv, inner.uv])
    patch = np.concatenate([np.repeat(np.arange(n_p), 4), side.patch, inner.patch])
    tris, tri_patch, strip_uv = _pattern_triangles(edges, side, inner, side_counts, n_in, n_c, spacing)
    return _welded(h, edges, positions, uv, patch, corners, inner, tris, tri_patch, strip_uv, n_c + len(side.points))


@dataclass
class _Points:
    """Vertices of one kind, before welding: points (n, 3), uv (n, 2) and patch (n,) (the patch whose (u, v) they
    are given in); ``first`` per side (E,) or per patch (P,): where its points start; for inner points ``normals``
    (n, 3) (unnormalised) and ``counts`` (P,); for side points ``params`` (E, max level + 1) when spaced."""

    points: np.ndarray
    uv: np.ndarray
    patch: np.ndarray
    first: np.ndarray
    normals: np.ndarray | None = None
    params: np.ndarray | None = None


def _side_points(h, edges, el, spacing):
    """The patches' corners (P, 4, 3): (0,0) (1,0) (1,1) (0,1), each on a collapsed side moved to that side's point
    (the poles of all patches around it are one point); and the sides' interior points (`_Points`, canonical order:
    every side evaluated once, its (u, v) in the first patch side that uses it)."""
    deg = h.shape[1] - 1
    corners = cartesian(h[:, [0, deg, deg, 0], [0, 0, deg, deg]])
    side_corners = ((0, 1), (1, 2), (3, 2), (0, 3))  # BOTTOM, RIGHT, TOP, LEFT: their corners in side direction
    for side, (a, b) in enumerate(side_corners):
        col = edges.collapsed[edges.edge[:, side]]
        corners[col, a] = edges.point[edges.edge[col, side]]
        corners[col, b] = edges.point[edges.edge[col, side]]
    counts = el - 1
    e_first = np.concatenate([[0], np.cumsum(counts)])[:-1]
    e_of = np.repeat(np.arange(len(el)), counts)
    kk = np.arange(len(e_of)) - e_first[e_of] + 1
    side_t = None if spacing is None else spacing.side_params(el)  # (E, max level + 1)
    t = kk / el[e_of] if spacing is None else side_t[e_of, kk]
    b = bernstein(t, deg)
    edge_pts = cartesian(np.matmul(b[:, None], edges.control[e_of])[:, 0])
    edge_pts[edges.collapsed[e_of]] = edges.point[e_of[edges.collapsed[e_of]]]  # exactly the one point
    # each edge's (patch, uv) for the vertex record: the first patch side that uses it
    sides = np.arange(len(h) * 4)
    first_side = np.full(len(el), len(sides), np.int64)
    np.minimum.at(first_side, edges.edge.ravel(), sides)
    fp, fs = first_side // 4, first_side % 4
    fr = edges.reversed.ravel()[first_side]
    tl = np.where(fr[e_of], 1.0 - t, t)
    side_uv = np.stack([np.select([fs[e_of] == 1, fs[e_of] == 3], [1.0, 0.0], tl),
                        np.select([fs[e_of] == 0, fs[e_of] == 2], [0.0, 1.0], tl)], 1)
    return corners, _Points(edge_pts, side_uv, fp[e_of], e_first, params=side_t)


def _inner_points(h, n_in, spacing):
    """Every patch's inner grid (`_Points` with normals): n_in (P, 2) steps along u and v, rows j of columns i; one
    tensor product per pair of inner counts."""
    deg = h.shape[1] - 1
    mu, mv = n_in[:, 0] - 1, n_in[:, 1] - 1
    count = mu * mv
    in_first = np.concatenate([[0], np.cumsum(count)])[:-1]
    inner_pts = np.empty((int(count.sum()), 3))
    inner_uv = np.empty((len(inner_pts), 2))
    inner_nrm = np.empty((len(inner_pts), 3))
    p_of = np.repeat(np.arange(len(h)), count)
    pairs, pair_of = np.unique(n_in, axis=0, return_inverse=True)
    for q, (nu, nv) in enumerate(pairs):  # one tensor product per pair of inner counts: rows j, columns i
        ps = np.flatnonzero((pair_of.ravel() == q) & (count > 0))
        if len(ps) == 0:
            continue
        if spacing is None:  # the bases shared by the group
            t_u, t_v = (np.arange(1, nu) / nu)[None], (np.arange(1, nv) / nv)[None]
            at_u, at_v = t_u[0], t_v[0]
        else:  # each patch its own
            t_u, t_v = spacing.inner_params(ps, 0, nu)[:, 1:-1], spacing.inner_params(ps, 1, nv)[:, 1:-1]
            at_u, at_v = t_u, t_v
        along_v = _contract_v(h[ps], at_v)
        along_dv = _contract_v_basis(h[ps], bernstein_derivative(at_v, deg))
        grid = _contract_u(along_v, at_u)  # coordinate planes (p, 4, V, U), and the derivatives'
        g_u = _contract_u_basis(along_v, bernstein_derivative(at_u, deg))
        g_v = _contract_u(along_dv, at_u)
        rows = in_first[ps][:, None] + np.arange((nu - 1) * (nv - 1))[None]
        w = grid[:, 3:]
        pts = grid[:, :3] / w
        inner_pts[rows] = _plane_points(pts)
        # the normal dS/du x dS/dv (up to w², which the division puts back), plane by plane
        a, b = g_u[:, :3] - pts * g_u[:, 3:], g_v[:, :3] - pts * g_v[:, 3:]
        w2 = w[:, 0] * w[:, 0]
        cross = np.stack([a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1], a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
                          a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]], axis=1)
        inner_nrm[rows] = _plane_points(cross / w2[:, None])
        jj, ii = np.divmod(np.arange((nu - 1) * (nv - 1)), nu - 1)
        inner_uv[rows] = np.stack(np.broadcast_arrays(t_u[:, ii], t_v[:, jj]), -1)
    return _Points(inner_pts, inner_uv, p_of, in_first, normals=inner_nrm)


def _pattern_triangles(edges, side, inner, side_counts, n_in, n_c, spacing):
    """Each patch's pattern over its vertices (corners from 0, side points from ``n_c``, inner points after them),
    one pattern class at a time: triangles (T, 3), their patch (T,), and the (u, v) of the strips' triangles (S, 3, 2)
    (a cell's are its inner points')."""
    base_e, base_i = n_c, n_c + len(side.points)
    tris, tri_patch, strip_uv = [], [], []
    keys = np.concatenate([side_counts, n_in], axis=1)
    classes, inverse = np.unique(keys, axis=0, return_inverse=True)
    for cls, key in enumerate(classes):
        ps = np.flatnonzero(inverse.ravel() == cls)
        tmpl = pattern(*(int(x) for x in key))
        cols = [4 * ps[:, None] + np.arange(4)[None]]
        for s in range(4):
            e, r = edges.edge[ps, s], edges.reversed[ps, s]
            q = np.arange(int(key[s]) - 1)[None]  # the side's interior points in the patch's direction
            cols.append(base_e + side.first[e][:, None] + np.where(r[:, None], q.shape[1] - 1 - q, q))
        cells = (int(key[4]) - 1) * (int(key[5]) - 1) if key[4] > 1 and key[5] > 1 else 0
        cols.append(base_i + inner.first[ps][:, None] + np.arange(cells)[None])
        lmap = np.concatenate(cols, 1)
        tri_patch.append(np.repeat(ps, len(tmpl)))
        if spacing is None:
            tris.append(lmap[:, tmpl].reshape(-1, 3))
            on_rim = tmpl[(tmpl < sum(int(c) for c in key[:4])).any(axis=1)]  # a corner or a side's point in it
            strip_uv.append(np.broadcast_to(_pattern_uv(tuple(int(x) for x in key))[on_rim],
                                            (len(ps),) + on_rim.shape + (2,)).reshape(-1, 3, 2))
        else:
            local_uv = _spaced_pattern_uv(ps, key, edges, side.params, inner.uv[cols[-1] - base_i])
            strip, cell_tris = _spaced_template(key, local_uv)
            own = strip.reshape(len(ps), -1)  # (p, 3S)
            tris.append(np.concatenate([np.take_along_axis(lmap, own, axis=1).reshape(len(ps), -1, 3),
                                        lmap[:, cell_tris]], axis=1).reshape(-1, 3))
            strip_uv.append(np.take_along_axis(local_uv, own[..., None], axis=1).reshape(-1, 3, 2))
    return np.concatenate(tris), np.concatenate(tri_patch), np.concatenate(strip_uv)


def _welded(h, edges, positions, uv, patch, corners, inner, tris, tri_patch, strip_uv, shared):
    """The `PatchMesh`: corners shared by patches and the points of collapsed sides merged where their positions are
    exactly equal (the first ``shared`` vertices; inner points are never merged), the triangles they flatten dropped,
    the strips' (u, v) at a pole moved, and the normals from the surface (a merged vertex takes the mean of its
    patches')."""
    base_i = shared
    # a cell's corners are all inner points (a strip's triangle has a corner or a side's point), which are never
    # merged: its corners' (u, v) are theirs, taken once the triangles are known
    is_cell = (tris >= base_i).all(axis=1)
    _, first, inv = np.unique(positions[:shared], axis=0, return_index=True, return_inverse=True)
    remap = np.concatenate([first[inv.ravel()], np.arange(shared, len(positions))])
    merged = remap[tris]
    keep = (merged[:, 0] != merged[:, 1]) & (merged[:, 1] != merged[:, 2]) & (merged[:, 0] != merged[:, 2])
    strip_uv = strip_uv[keep[~is_cell]]  # only strips flatten (at a pole)
    if edges.collapsed.any():  # only the strips' triangles with a corner on a pole move
        strip_patch = tri_patch[~is_cell & keep]
        near = np.flatnonzero(edges.collapsed[edges.edge].any(axis=1)[strip_patch]
                              & (((strip_uv == 0) | (strip_uv == 1)).any(axis=(1, 2))))
        strip_uv[near] = _pole_corners(strip_uv[near], edges.collapsed[edges.edge[strip_patch[near]]])
    uv32 = uv.astype(np.float32)
    tri_uv = uv32[tris[keep][:, ::-1]]  # reversed, as the triangles are below; the strips' then set
    tri_uv[np.flatnonzero(~is_cell[keep])] = strip_uv[:, ::-1]
    tris, tri_patch = merged[keep], tri_patch[keep]
    used = np.zeros(len(positions), bool)
    used[tris.ravel()] = True
    new_id = np.cumsum(used) - 1
    # normals from the surface (corners and sides from their first patch, a vanishing one a little inside it); a
    # merged vertex (a pole) gets the mean of its patches' normals there
    _, normals = _point_and_normal(h[patch[:shared]], uv[:shared, 0], uv[:shared, 1])
    inner_nrm = inner.normals
    length = np.linalg.norm(inner_nrm, axis=1)
    weak = np.flatnonzero(length <= 1e-12 * (1.0 + np.abs(corners).max()) ** 2)
    if len(weak):
        inner_nrm[weak] = _point_and_normal(h[inner.patch[weak]], inner.uv[weak, 0], inner.uv[weak, 1])[1]
        length[weak] = 1.0
    summed = np.zeros_like(normals)  # inner points are never merged: only the shared ones are summed
    np.add.at(summed, remap[:shared], normals)
    length_s = np.linalg.norm(summed, axis=1, keepdims=True)
    normals = np.where(length_s > 0, summed / np.where(length_s > 0, length_s, 1.0), normals)
    normals = np.concatenate([normals, inner_nrm / np.where(length > 0, length, 1.0)[:, None]])
    # Blender's orientation: the pattern's counter-clockwise (u, v) triangles reversed, the normals along dS/dv x dS/du
    return PatchMesh(positions[used].astype(np.float32), new_id[tris[:, ::-1]].astype(np.int32),
                     uv32[used], patch[used], tri_patch, tri_uv,
                     -normals[used].astype(np.float32))

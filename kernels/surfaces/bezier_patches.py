"""Bicubic Bézier patches tessellated with per-patch, per-boundary levels, welded with no T-junction ([Nellmedin 2014,
§4.3, §5.5.3]; the Utah teapot's kind of model).

A patch is its 4 x 4 control net ``P[i, j]`` (i along u, j along v), ``P(u, v) = Σ B_i(u) B_j(v) P[i, j]``.
Sides, in the pattern's order (`kernels.common.quad_pattern.pattern`): BOTTOM v = 0 (u from 0 to 1), RIGHT u = 1 (v
up), TOP v = 1 (u up), LEFT u = 0 (v up). A side is a cubic of its 4 control points only, so it is one edge shared
by the patches that have those 4 points: each edge is keyed by its control points in a canonical direction, its
level computed once from them and its points evaluated once, in that direction; a patch reads them forwards or
backwards. Corners are control points. Shared boundaries are therefore one set of vertices (welded by
construction) and no crack or T-junction can appear. A boundary that collapses to a point (the teapot's lid top
and bottom centre) gives the same point L + 1 times: such points are merged and the triangles they flatten
dropped. Such a collapsed row has κ⁺ = 0/0: it counts as the cap by default, as [Nellmedin 2014]'s GPU did ([Nellmedin
2014, item 5; `PatchLod.degenerate`), which with the knob's fold is what makes the teapot's knob and base its finest
patches.

Levels (`patch_levels`):
- curvature: a side's level from its own control polygon (eq. 4.5, min 6, max Max Level); the inner levels from
  the rows (u) and the columns (v) of the net (``inner_rows`` ALL, [Nellmedin 2014]'s §4.1.2, or INTERIOR, its §5.3.3:
  [Nellmedin 2014, correction 3]) and the 9 cells' diagonal κ× (eq. 4.6): if the largest κ× exceeds both, it sets both;
- distance: a side from the smallest distance of its 4 control points to the eye, the inner from the net's
  centroid, through the linear (or inverse) map between Near and Far;
- projected edge length (§4.4): a side as a sphere as wide as its control polygon is long, at its centroid, over
  Edge Pixels; the inside from the net's longest row or column at its centroid;
- any of these together: the largest. Levels are whole segment counts; one inner count per patch, the larger of u
  and v (the pattern's single inner level).
"""

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..common.errors import InvalidInputError
from ..common.level_metrics import curvature_level, curve_kappa, distance_level, projected_sphere_levels
from ..common.quad_pattern import pattern, pattern_codes

METRICS = ("CURVATURE", "DISTANCE", "EDGE_LENGTH")
MAX_LEVEL = 64
#: Control-net indices (i, j) of each side, in the side's direction.
_SIDES = (
    [(i, 0) for i in range(4)],   # BOTTOM
    [(3, j) for j in range(4)],   # RIGHT
    [(i, 3) for i in range(4)],   # TOP
    [(0, j) for j in range(4)],   # LEFT
)


@dataclass(frozen=True)
class PatchLod:
    """How levels are chosen: metrics, some of CURVATURE, DISTANCE, EDGE_LENGTH (combined by maximum); max_level
    (≤ 64, the curvature metric's cap t_tessmax); inner_rows ALL or INTERIOR; near, far, mapping (LINEAR or
    INVERSE): the distance map; edge_pixels: the projected-edge metric's segment length on screen; degenerate:
    what a row of the net that collapses to one point (κ⁺ = 0/0) counts for the inner levels: CAP ([Nellmedin 2014]'s
    GPU, and what makes the teapot's knob and base its finest patches; [Nellmedin 2014, correction 4]) or ZERO (no
    bend)."""

    metrics: tuple = ("CURVATURE",)
    max_level: int = 32
    inner_rows: str = "ALL"
    near: float = 1.0
    far: float = 20.0
    mapping: str = "LINEAR"
    edge_pixels: float = 10.0
    degenerate: str = "CAP"

    def __post_init__(self):
        if not self.metrics or not set(self.metrics) <= set(METRICS):
            raise InvalidInputError(f"metrics must be some of {', '.join(METRICS)}; got {self.metrics!r}")
        if not (np.isfinite(self.edge_pixels) and self.edge_pixels > 0):
            raise InvalidInputError(f"Edge Pixels must be a positive number; got {self.edge_pixels!r}")
        if self.degenerate not in ("CAP", "ZERO"):
            raise InvalidInputError(f"degenerate must be CAP or ZERO; got {self.degenerate!r}")
        if self.inner_rows not in ("ALL", "INTERIOR"):
            raise InvalidInputError(f"inner_rows must be ALL or INTERIOR; got {self.inner_rows!r}")
        if not 1 <= self.max_level <= MAX_LEVEL:
            raise InvalidInputError(f"Max Level must be from 1 to {MAX_LEVEL}; got {self.max_level!r}")


@dataclass
class PatchEdges:
    """The patches' sides as shared edges. control: (E, 4, 3) each edge's control points in its canonical
    direction; edge: (P, 4) the edge of each patch side; reversed: (P, 4) whether the side runs against it."""

    control: np.ndarray
    edge: np.ndarray
    reversed: np.ndarray


@dataclass
class PatchMesh:
    """positions (V, 3) float32; triangles (T, 3) int32 (counter-clockwise in each patch's (u, v)); uv (V, 2)
    float32 and patch (V,) int64: where each vertex was evaluated (a shared vertex: its first patch);
    triangle_patch (T,) int64 and corner_uv (T, 3, 2) float32: each triangle's patch and its corners' (u, v) in it."""

    positions: np.ndarray
    triangles: np.ndarray
    uv: np.ndarray
    patch: np.ndarray
    triangle_patch: np.ndarray
    corner_uv: np.ndarray


def bernstein(t):
    """Cubic Bernstein basis (..., 4) at t (...)."""
    t = np.asarray(t, np.float64)[..., None]
    s = 1.0 - t
    return np.concatenate([s ** 3, 3 * s * s * t, 3 * s * t * t, t ** 3], axis=-1)


def evaluate(control, u, v):
    """Points of patches: control (P, 4, 4, 3), u and v (P, k) -> (P, k, 3)."""
    bu, bv = bernstein(u), bernstein(v)
    return np.einsum("pki,pkj,pijc->pkc", bu, bv, np.asarray(control, np.float64))


def check_patches(control):
    c = np.asarray(control, np.float64)
    if c.ndim != 4 or c.shape[1:] != (4, 4, 3) or len(c) == 0:
        raise InvalidInputError(f"Bicubic patches need (P, 4, 4, 3) control points; got {c.shape}")
    if not np.all(np.isfinite(c)):
        raise InvalidInputError("The surface has control points that are NaN or infinite")
    return c


def patch_edges(control):
    """Key every patch side by its control points: a `PatchEdges`."""
    c = check_patches(control)
    sides = np.stack([c[:, [i for i, _ in s], [j for _, j in s]] for s in _SIDES], axis=1)  # (P, 4, 4, 3)
    flat = sides.reshape(-1, 4, 3)
    back = flat[:, ::-1]
    fwd_key, back_key = flat.reshape(len(flat), -1), back.reshape(len(flat), -1)
    # canonical: the lexicographically smaller of the two directions (exact comparison of the float64 values)
    rev = np.array([tuple(b) < tuple(f) for f, b in zip(fwd_key, back_key, strict=True)])
    canon = np.where(rev[:, None, None], back, flat)
    _, first, edge = np.unique(canon.reshape(len(canon), -1), axis=0, return_index=True, return_inverse=True)
    return PatchEdges(canon[first], edge.reshape(-1, 4), rev.reshape(-1, 4))


def _eq45(kappa, max_level):
    return np.ceil(curvature_level(kappa, n_control=4, t_max=float(max_level))).astype(np.int64)


def diagonal_kappa(control):
    """Eq. 4.6 per cell of each net: ½ |P[i+1,j+1] + P[i,j] - P[i+1,j] - P[i,j+1]| / min(diagonals), the largest
    of the 9 cells: (P, 4, 4, 3) -> (P,). A cell whose diagonals both vanish counts as 0 (nothing to split)."""
    c = np.asarray(control, np.float64)
    a, b, d, e = c[:, :-1, :-1], c[:, 1:, 1:], c[:, 1:, :-1], c[:, :-1, 1:]
    num = 0.5 * np.linalg.norm(b + a - d - e, axis=-1)
    den = np.minimum(np.linalg.norm(b - a, axis=-1), np.linalg.norm(e - d, axis=-1))
    k = np.divide(num, den, out=np.where(num > 0, np.inf, 0.0), where=den > 0)
    return k.reshape(len(c), -1).max(axis=1)


def _polygon_length(points):
    """Lengths of control polygons (..., n, 3) -> (...): an upper bound of their curves' lengths."""
    return np.linalg.norm(np.diff(points, axis=-2), axis=-1).sum(axis=-1)


def patch_levels(control, edges, lod, camera=None):
    """Levels: (edge levels (E,) int64, inner levels (P,) int64) in [1, max_level]. camera: a
    `kernels.common.camera.Camera` in the patches' space, for DISTANCE and EDGE_LENGTH."""
    c = check_patches(control)
    edge_level = np.ones(len(edges.control), np.int64)
    inner = np.ones(len(c), np.int64)
    if (set(lod.metrics) & {"DISTANCE", "EDGE_LENGTH"}) and camera is None:
        raise InvalidInputError("Distance and edge-length levels need a camera")
    if "CURVATURE" in lod.metrics:
        edge_level = np.maximum(edge_level, _eq45(curve_kappa(edges.control), lod.max_level))
        rows = slice(None) if lod.inner_rows == "ALL" else slice(1, 3)
        along_u, along_v = c[:, :, rows].transpose(0, 2, 1, 3), c[:, rows, :]  # (P, rows, 4, 3) each
        k_u, k_v = curve_kappa(along_u), curve_kappa(along_v)
        if lod.degenerate == "CAP":
            k_u = np.where(np.all(along_u == along_u[:, :, :1], axis=(2, 3)), np.inf, k_u)
            k_v = np.where(np.all(along_v == along_v[:, :, :1], axis=(2, 3)), np.inf, k_v)
        k_u, k_v = k_u.max(axis=1), k_v.max(axis=1)
        k_x = diagonal_kappa(c)
        diag = k_x > np.maximum(k_u, k_v)
        k_in = np.where(diag, k_x, np.maximum(k_u, k_v))
        inner = np.maximum(inner, _eq45(k_in, lod.max_level))
    if "EDGE_LENGTH" in lod.metrics:  # a sphere of the control polygon's length, at its centroid (§4.4)
        view = np.asarray(camera.view, np.float64)

        def projected(centre, length):
            m = centre @ view[:3, :3].T + view[:3, 3]
            t = projected_sphere_levels(m, length, camera.projection, camera.height, lod.edge_pixels,
                                        float(lod.max_level))
            return np.ceil(t).astype(np.int64)

        edge_level = np.maximum(edge_level, projected(edges.control.mean(axis=1), _polygon_length(edges.control)))
        size = np.maximum(_polygon_length(c).max(axis=1), _polygon_length(c.transpose(0, 2, 1, 3)).max(axis=1))
        inner = np.maximum(inner, projected(c.reshape(len(c), -1, 3).mean(axis=1), size))
    if "DISTANCE" in lod.metrics:
        eye = camera.eye
        d_edge = np.linalg.norm(edges.control - eye, axis=-1).min(axis=1)
        d_in = np.linalg.norm(c.reshape(len(c), -1, 3).mean(axis=1) - eye, axis=-1)

        def dist(d):
            return np.ceil(distance_level(d, lod.near, lod.far, float(lod.max_level), lod.mapping)).astype(np.int64)

        edge_level = np.maximum(edge_level, dist(d_edge))
        inner = np.maximum(inner, dist(d_in))
    return np.minimum(edge_level, lod.max_level), np.minimum(inner, lod.max_level)


def tessellate_patches(control, edge_levels, inner_levels, edges=None):
    """The welded triangle mesh of the patches at these levels: a `PatchMesh`."""
    c = check_patches(control)
    edges = edges or patch_edges(c)
    n_p = len(c)
    el = np.asarray(edge_levels, np.int64)
    # vertices: corners (4 per patch, merged below), edge interior points (canonical order), inner grids
    corners = c[:, [0, 3, 3, 0], [0, 0, 3, 3]]  # (P, 4, 3): (0,0) (1,0) (1,1) (0,1)
    corner_uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float64)
    counts = el - 1
    e_first = np.concatenate([[0], np.cumsum(counts)])[:-1]
    e_of = np.repeat(np.arange(len(el)), counts)
    k = np.arange(len(e_of)) - e_first[e_of] + 1
    t = k / el[e_of]
    b = bernstein(t)
    edge_pts = np.einsum("nk,nkc->nc", b, edges.control[e_of])
    collapsed = np.all(edges.control == edges.control[:, :1], axis=(1, 2))  # a side that is one point
    edge_pts[collapsed[e_of]] = edges.control[e_of[collapsed[e_of]], 0]  # exactly (Σ B_k(t) need not round to 1)
    # each edge's (patch, uv) for the vertex record: the first patch side that uses it
    sides = np.arange(n_p * 4)
    first_side = np.full(len(el), len(sides), np.int64)
    np.minimum.at(first_side, edges.edge.ravel(), sides)
    fp, fs = first_side // 4, first_side % 4
    fr = edges.reversed.ravel()[first_side]
    tl = np.where(fr[e_of], 1.0 - t, t)
    side_uv = np.stack([np.select([fs[e_of] == 1, fs[e_of] == 3], [1.0, 0.0], tl),
                        np.select([fs[e_of] == 0, fs[e_of] == 2], [0.0, 1.0], tl)], 1)
    n_in = np.maximum(np.asarray(inner_levels, np.int64), 1)
    side_counts = el[edges.edge]  # (P, 4)
    one = side_counts == 1
    strip = (one[:, 1] & one[:, 3]) | (one[:, 0] & one[:, 2])  # as terrain tiles: a single strip
    n_in = np.where((n_in == 1) & ~strip, 2, n_in)
    m = n_in - 1
    in_first = np.concatenate([[0], np.cumsum(m * m)])[:-1]
    inner_pts = np.empty((int((m * m).sum()), 3))
    inner_uv = np.empty((len(inner_pts), 2))
    p_of = np.repeat(np.arange(n_p), m * m)
    for n in np.unique(n_in[m > 0]):  # one tensor product per inner count: rows j, columns i, as the pattern
        ps = np.flatnonzero(n_in == n)
        t_in = np.arange(1, n) / n
        b_in = bernstein(t_in)
        grid = np.einsum("ik,jl,pklc->pjic", b_in, b_in, c[ps], optimize=True).reshape(len(ps), -1, 3)
        rows = in_first[ps][:, None] + np.arange((n - 1) ** 2)[None]
        inner_pts[rows] = grid
        jj, ii = np.divmod(np.arange((n - 1) ** 2), n - 1)
        inner_uv[rows] = np.stack([t_in[ii], t_in[jj]], 1)[None]

    n_c = 4 * n_p
    base_e, base_i = n_c, n_c + len(edge_pts)
    positions = np.concatenate([corners.reshape(-1, 3), edge_pts, inner_pts])
    uv = np.concatenate([np.tile(corner_uv, (n_p, 1)), side_uv, inner_uv])
    patch = np.concatenate([np.repeat(np.arange(n_p), 4), fp[e_of], p_of])

    tris, tri_patch, tri_uv = [], [], []
    keys = np.concatenate([side_counts, n_in[:, None]], axis=1)
    classes, inverse = np.unique(keys, axis=0, return_inverse=True)
    for cls, key in enumerate(classes):
        ps = np.flatnonzero(inverse.ravel() == cls)
        tmpl = pattern(*(int(x) for x in key))
        cols = [4 * ps[:, None] + np.arange(4)[None]]
        for side in range(4):
            e, r = edges.edge[ps, side], edges.reversed[ps, side]
            q = np.arange(int(key[side]) - 1)[None]  # the side's interior points in the patch's direction
            cols.append(base_e + e_first[e][:, None] + np.where(r[:, None], q.shape[1] - 1 - q, q))
        mloc = int(key[4]) - 1
        cols.append(base_i + in_first[ps][:, None] + np.arange(mloc * mloc)[None])
        lmap = np.concatenate(cols, 1)
        tris.append(lmap[:, tmpl].reshape(-1, 3))
        tri_patch.append(np.repeat(ps, len(tmpl)))
        local_uv = _pattern_uv(tuple(int(x) for x in key))
        tri_uv.append(np.broadcast_to(local_uv[tmpl], (len(ps),) + tmpl.shape + (2,)).reshape(-1, 3, 2))
    tris, tri_patch, tri_uv = np.concatenate(tris), np.concatenate(tri_patch), np.concatenate(tri_uv)
    # corners shared by patches, and points of collapsed sides, are the same point: merge exactly equal positions
    # of corners and side points (inner points are never merged)
    shared = n_c + len(edge_pts)
    _, first, inv = np.unique(positions[:shared], axis=0, return_index=True, return_inverse=True)
    remap = np.concatenate([first[inv.ravel()], np.arange(shared, len(positions))])
    tris = remap[tris]
    keep = (tris[:, 0] != tris[:, 1]) & (tris[:, 1] != tris[:, 2]) & (tris[:, 0] != tris[:, 2])
    tris, tri_patch, tri_uv = tris[keep], tri_patch[keep], tri_uv[keep]
    used = np.zeros(len(positions), bool)
    used[tris.ravel()] = True
    new_id = np.cumsum(used) - 1
    return PatchMesh(positions[used].astype(np.float32), new_id[tris].astype(np.int32),
                     uv[used].astype(np.float32), patch[used], tri_patch, tri_uv.astype(np.float32))


@lru_cache(maxsize=4096)
def _pattern_uv(key):
    """(u, v) of each local vertex of the pattern of class key (c0, c1, c2, c3, n), from its `pattern_codes`:
    corners, side points k / c in each side's direction, inner (i / n, j / n)."""
    codes = pattern_codes(*key)
    kind, a, b = codes[:, 0].astype(int), codes[:, 1].astype(np.float64), codes[:, 2].astype(np.float64)
    c = np.asarray(key[:4], np.float64)
    n = float(key[4])
    t = np.divide(a, c[np.clip(kind - 1, 0, 3)])
    u = np.select([kind == 0, kind == 1, kind == 2, kind == 3, kind == 4], [a, t, 1.0, t, 0.0], a / n)
    v = np.select([kind == 0, kind == 1, kind == 2, kind == 3, kind == 4], [b, 0.0, t, 1.0, t], b / n)
    return np.stack([u, v], 1)

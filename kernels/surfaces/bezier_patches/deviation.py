"""How far a patch's triangles stray from the surface: the inner grids' cells (`grid_deviation`) and the strips along
the sides (`rim_triangles`), on the CPU or the OpenCL device (`patch_deviation_opencl`), at the points `_B` of each
triangle."""


import numpy as np

from ...common import workers
from ...common.curves import step_spacing
from ...common.curves.rational_bezier import (
    bernstein,
)
from ...common.quad_pattern import pattern
from .. import patch_deviation_opencl
from .nets import _contract_u_basis, _contract_v_basis, _grid_at, check_patches, evaluate, inner_pairs
from .pattern_uv import _pattern_counts, _pattern_uv, _pole_corners, _spaced_pattern_uv, _spaced_template

#: Barycentric points where each triangle is measured against the surface: its edges' midpoints, its centroid and
#: the points halfway from the centroid to each corner (where the deviation of a smooth surface from a small
#: triangle is largest).
_B = np.array([[.5, .5, 0], [0, .5, .5], [.5, 0, .5], [1 / 3, 1 / 3, 1 / 3], [2 / 3, 1 / 6, 1 / 6],
               [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]])

#: With spaced steps, `grid_deviation` measures patches together whose counts round up to the same multiple of this.
GRID_BUCKET = 8

#: `grid_deviation` measures at most this many cells at once (a few float64 arrays of 4 values a cell).
GRID_CELLS = 1 << 18

def triangle_deviation(control, mesh, which=None):
    """The largest distance between each triangle and the surface: (T,) float64. Each of `_B`'s barycentric points
    of a triangle is compared with the surface at the same barycentric point of its corners' (u, v) — the mesh's
    map to the surface — so this bounds the distance both ways where the points are dense enough. which: (T',)
    the triangles to measure (all by default); the result is theirs."""
    h = check_patches(control)
    which = np.arange(len(mesh.triangles)) if which is None else np.asarray(which, np.int64)
    return _deviation(h, mesh.positions.astype(np.float64)[mesh.triangles[which]],
                      mesh.corner_uv[which].astype(np.float64), mesh.triangle_patch[which])

def _deviation(h, corners, uv, patch, runtime=None):
    """`triangle_deviation` of triangles given by their corners' positions (T, 3, 3), (u, v) (T, 3, 2) and
    patch (T,): (T,) float64; on ``runtime``'s OpenCL device where it has double precision
    (`patch_deviation_opencl`)."""
    if patch_deviation_opencl.supports(runtime):
        return patch_deviation_opencl.triangle_deviation(runtime, h, corners, uv, patch, _B)
    on_mesh = np.matmul(_B, corners)
    at = np.matmul(_B, uv)
    out = np.empty(len(corners))
    for chunk in np.array_split(np.arange(len(corners)), max(1, len(corners) // 65536)):
        s = evaluate(h[patch[chunk]], at[chunk, :, 0], at[chunk, :, 1])
        out[chunk] = np.linalg.norm(on_mesh[chunk] - s, axis=-1).max(axis=1)
    return out

def rim_triangles(control, edge_levels, inner_levels, edges, spacing, which, runtime=None):
    """The triangles of patches ``which`` (p,) that reach a side of their patch, as `tessellate_patches` makes
    them (a triangle flattened at a pole dropped, its fan's corner (u, v) at the pole moved as there), without
    making the mesh: (corners (R, 3, 3) positions, (u, v) (R, 3, 2), both rounded to float32 as the mesh stores
    them, patch (R,) int64). The corners are evaluated on ``runtime``'s OpenCL device where it has double precision
    (`patch_deviation_opencl.points`)."""
    h = check_patches(control)
    el = np.asarray(edge_levels, np.int64)
    side_counts = el[edges.edge]
    n_in = _pattern_counts(inner_pairs(inner_levels, len(h)), side_counts)
    side_t = None if spacing is None else spacing.side_params(el)
    keys = np.concatenate([side_counts, n_in], axis=1)[which]
    classes, inverse = np.unique(keys, axis=0, return_inverse=True)
    uvs, patches = [], []
    for cls, key in enumerate(classes):
        ps = np.asarray(which)[inverse.ravel() == cls]
        key_t = tuple(int(x) for x in key)
        if spacing is None:
            tmpl = pattern(*key_t)
            on_rim = (tmpl < sum(key_t[:4])).any(axis=1)  # a corner on a side: corners and sides' points come first
            local = np.broadcast_to(_pattern_uv(key_t), (len(ps),) + _pattern_uv(key_t).shape)
            own = np.broadcast_to(tmpl[on_rim], (len(ps),) + tmpl[on_rim].shape)
        else:
            nu, nv = key_t[4], key_t[5]
            cells = (nu - 1) * (nv - 1) if nu > 1 and nv > 1 else 0
            jj, ii = np.divmod(np.arange(cells), max(nu - 1, 1))
            t_u, t_v = spacing.inner_params(ps, 0, nu), spacing.inner_params(ps, 1, nv)
            inner = np.stack([t_u[:, ii + 1], t_v[:, jj + 1]], axis=-1)
            local = _spaced_pattern_uv(ps, key, edges, side_t, inner)
            own = _spaced_template(key, local)[0]  # the strips: the triangles along the sides
        uvs.append(np.take_along_axis(local, own.reshape(len(ps), -1)[..., None], axis=1).reshape(-1, 3, 2))
        patches.append(np.repeat(ps, own.shape[1]))
    if not uvs:
        return np.zeros((0, 3, 3)), np.zeros((0, 3, 2)), np.zeros(0, np.int64)
    uv, patch = np.concatenate(uvs), np.concatenate(patches)
    collapsed = edges.collapsed[edges.edge[patch]]  # (R, 4) BOTTOM, RIGHT, TOP, LEFT
    u, v = uv[..., 0], uv[..., 1]
    on = np.stack([(v == 0) & collapsed[:, :1], (u == 1) & collapsed[:, 1:2], (v == 1) & collapsed[:, 2:3],
                   (u == 0) & collapsed[:, 3:]], axis=-1)  # (R, 3 corners, 4 sides)
    if patch_deviation_opencl.supports(runtime):
        corners = patch_deviation_opencl.points(runtime, h, uv.reshape(-1, 2), np.repeat(patch, 3)).reshape(-1, 3, 3)
    else:
        corners = evaluate(h[patch], uv[..., 0], uv[..., 1])
    at_pole = on.any(axis=2)
    if at_pole.any():  # the one point of the pole, as the mesh has it; two corners there: flattened, dropped
        side = on.argmax(axis=2)
        corners[at_pole] = edges.point[edges.edge[np.broadcast_to(patch[:, None], side.shape), side][at_pole]]
        same = [at_pole[:, a] & at_pole[:, b] & (corners[:, a] == corners[:, b]).all(axis=1)
                for a, b in ((0, 1), (1, 2), (0, 2))]
        keep = ~(same[0] | same[1] | same[2])
        corners, uv, patch = corners[keep], uv[keep], patch[keep]
        uv = _pole_corners(uv, edges.collapsed[edges.edge[patch]])
    as_stored = np.float32
    return corners.astype(as_stored).astype(np.float64), uv.astype(as_stored).astype(np.float64), patch

def grid_deviation(control, inner_levels, spacing=None, points=_B, runtime=None):
    """The largest distance between the surface and the triangles of each patch's inner grid (the cells between
    its inner points (i / n, j / m), or where ``spacing`` (a `Spacing`) puts them, each cut along its
    (i, j)-(i+1, j+1) diagonal as the pattern cuts it), measured at `_B` (or the barycentric ``points`` given) in
    every triangle as `triangle_deviation` does, by tensor products (one per pair of inner levels; the groups, or
    halves of them, on worker threads: `kernels.common.workers`), or on ``runtime``'s OpenCL device where it has
    double precision (`patch_deviation_opencl`: the same points and parameters). Returns (P, 3) float64: the largest
    distance anywhere, at the cells' sides along u, and along v (0 for a patch with fewer than 2 cells a way)."""
    h = check_patches(control)
    n_in = inner_pairs(inner_levels, len(h))
    out = np.zeros((len(h), 3))
    ok = (n_in >= 3).all(axis=1)
    if patch_deviation_opencl.supports(runtime):
        ps = np.flatnonzero(ok)
        if spacing is None:
            tu, tv = (step_spacing.padded_params(np.array([[0.0, 1.0]]).repeat(len(ps), 0), n_in[ps, axis])
                      for axis in (0, 1))
        else:
            tu, tv = (step_spacing.padded_params(spacing.inner[ps, axis], n_in[ps, axis]) for axis in (0, 1))
        out[ps] = patch_deviation_opencl.grid_deviation(runtime, h[ps], n_in[ps], tu, tv, points)
        return out
    # equal steps: one group a pair of counts (the bases shared); spaced steps (each patch its own bases): counts
    # rounded up to a multiple of GRID_BUCKET, the cells past a patch's own count empty
    key = n_in if spacing is None else -(-n_in // GRID_BUCKET) * GRID_BUCKET
    pairs, pair_of = np.unique(key, axis=0, return_inverse=True)
    jobs = []
    for q, (nu, nv) in enumerate(pairs):
        ps = np.flatnonzero((pair_of.ravel() == q) & ok)
        if len(ps):  # a share for each thread, and at most GRID_CELLS cells a job (its arrays' memory)
            parts = max(min(len(ps), workers.WORKERS + 1), -(-len(ps) * int(nu) * int(nv) // GRID_CELLS))
            jobs += [(part, int(nu), int(nv)) for part in np.array_split(ps, min(parts, len(ps)))]
    if not jobs:
        return out

    def run(job):
        ps, nu, nv = job
        out[ps] = _grid_group(h[ps], nu, nv, None if spacing is None else spacing.of(ps), points, n_in[ps])

    if workers.in_worker():
        for job in jobs:
            run(job)
        return out
    with workers.parallel_section():
        done = [workers.submit(run, job) for job in jobs[1:]]
        run(jobs[0])
        for future in done:
            future.result()
    return out

def _grid_group(h, nu, nv, spacing, points, counts):
    """`grid_deviation` of nets h (p, k, k, 4) that all step nu along u and nv along v (equal steps), or whose own
    counts (p, 2) are at most that (spaced steps: their parameters past their own last inner point stay there, so
    the cells past it are empty): (p, 3)."""
    d = h.shape[1] - 1
    out = np.zeros((len(h), 3))
    tri_offsets = (np.array([[0, 0], [1, 0], [1, 1]], np.float64), np.array([[0, 0], [1, 1], [0, 1]], np.float64))
    # the cells' corners (the inner grid) and each sample point of every cell, by offsets a in each direction:
    # the v basis contracted once per distinct a along v, then the u basis per sample
    cu, cv = np.arange(1, nu - 1), np.arange(1, nv - 1)
    if spacing is None:
        tu, tv = (np.arange(nu + 1) / nu)[None], (np.arange(nv + 1) / nv)[None]

        def at(t, c, a, n):
            return (c + a) / n
    else:
        tu, tv = (_padded_inner(spacing.inner[:, axis], counts[:, axis], n) for axis, n in ((0, nu), (1, nv)))

        def at(t, c, a, n):
            return t[:, c] + a * (t[:, c + 1] - t[:, c])
    g = _grid_at(h, tu[:, 1:-1], tv[:, 1:-1])
    corners = g[:, :3] / g[:, 3:]  # (p, 3, nv - 1, nu - 1)
    # every sample's offsets in its cell are sixths: the bases at each, computed together
    sixths = np.arange(7) / 6
    b_u = bernstein(np.stack([at(tu, cu, a, nu) for a in sixths]), d)  # (7, [p,] U, k)
    b_v = bernstein(np.stack([at(tv, cv, a, nv) for a in sixths]), d)
    along_v = {}
    for offs in tri_offsets:
        c0, c1, c2 = (corners[:, :, int(dv):int(dv) + nv - 2, int(du):int(du) + nu - 2] for du, dv in offs)
        c1, c2 = c1 - c0, c2 - c0
        for bary in points:
            iu, iv = (round(float(x) * 6) for x in bary @ offs)
            if iv not in along_v:
                along_v[iv] = _contract_v_basis(h, b_v[iv])
            on = _contract_u_basis(along_v[iv], b_u[iu])  # (p, 4, V, U) homogeneous
            gap = on[:, :3] / on[:, 3:] - c0
            gap -= bary[1] * c1
            gap -= bary[2] * c2
            gap *= gap
            dev = np.sqrt((gap[:, 0] + gap[:, 1] + gap[:, 2]).reshape(len(h), -1).max(axis=1))
            a = bary @ offs
            out[:, 0] = np.maximum(out[:, 0], dev)
            if a[1] in (0.0, 1.0):  # on a side of the cell along u
                out[:, 1] = np.maximum(out[:, 1], dev)
            elif a[0] in (0.0, 1.0):  # along v
                out[:, 2] = np.maximum(out[:, 2], dev)
    return out

def _padded_inner(cum, counts, n):
    """Parameters (p, n + 1) of each table cum (p, M + 1) at its own count (p,) <= n, the values past its last
    inner point (counts - 1) held there."""
    t = step_spacing.padded_params(cum, counts)
    t = np.concatenate([t, np.ones((len(t), n + 1 - t.shape[1]))], axis=1) if t.shape[1] < n + 1 else t[:, :n + 1]
    last = counts - 1
    held = np.arange(n + 1)[None] > last[:, None]
    return np.where(held, t[np.arange(len(t)), last][:, None], t)

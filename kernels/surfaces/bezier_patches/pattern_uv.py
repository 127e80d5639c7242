"""The (u, v) of a patch's pattern: the quad pattern of its side and inner counts, with its steps moved where the
surface bends (spaced), and the corners a collapsed side makes one point."""

from functools import lru_cache

import numpy as np

from ...common.quad_pattern import pattern, pattern_codes, strips, zip_by_params


def _spaced_template(key, local_uv):
    """The triangles of the pattern of class key, for patches whose points lie at local_uv (p, L, 2) (spaced
    steps), in local indices: (strips (p, S, 3), each patch's own: each strip zipped by the points' parameters
    (`kernels.common.quad_pattern.zip_by_params`), so a side finer than the grid beside it meets it without skew;
    cells (C, 3), the inner grid's as `pattern` makes them, the same for all). A strip tile (an inner count of 1)
    is all strip."""
    key_t = tuple(int(x) for x in key)
    tmpl = pattern(*key_t)
    if key_t[4] < 2 or key_t[5] < 2:  # a strip tile: no ring to meet
        return np.broadcast_to(tmpl, (len(local_uv),) + tmpl.shape), tmpl[:0]
    rows, ring, _ = strips(*key_t)
    parts, n_strip = [], 0
    for side in range(4):
        t_row, t_ring = local_uv[:, rows[side], side % 2], local_uv[:, ring[side], side % 2]
        if side >= 2:  # TOP and LEFT run against u and v
            t_row, t_ring = 1.0 - t_row, 1.0 - t_ring
        parts.append(zip_by_params(rows[side], ring[side], t_row, t_ring))
        n_strip += len(rows[side]) + len(ring[side]) - 2
    return np.concatenate(parts, axis=1), tmpl[n_strip:]

def _pattern_counts(n_in, side_counts):
    """The inner steps (P, 2) the pattern is made with: as terrain tiles, one step along u is a strip between the
    left and right sides when the bottom and top are one segment each (and along v likewise); else at least 2."""
    one = side_counts == 1
    return np.stack([np.where((n_in[:, 0] == 1) & ~(one[:, 0] & one[:, 2]), 2, n_in[:, 0]),
                     np.where((n_in[:, 1] == 1) & ~(one[:, 1] & one[:, 3]), 2, n_in[:, 1])], 1)

def _spaced_pattern_uv(ps, key, edges, side_t, inner):
    """(u, v) (p, L, 2) of each local vertex of the pattern of class key for patches ps (p,) whose steps are
    spaced: corners, each side's points at its edge's parameters (side_t (E, ·), canonical direction) read in the
    patch's direction, and the inner points' (u, v) inner (p, (n - 1)(m - 1), 2)."""
    counts = [int(c) for c in key[:4]]
    out = np.empty((len(ps), sum(counts) + inner.shape[1], 2))
    out[:, :4] = [[0, 0], [1, 0], [1, 1], [0, 1]]
    start = 4
    for side, c in enumerate(counts):
        e, r = edges.edge[ps, side], edges.reversed[ps, side]
        q = np.arange(1, c)[None]
        t = side_t[e[:, None], np.where(r[:, None], c - q, q)]
        along, fixed = (0, 1) if side in (0, 2) else (1, 0)  # BOTTOM, TOP run along u; RIGHT, LEFT along v
        out[:, start:start + c - 1, along] = np.where(r[:, None], 1.0 - t, t)
        out[:, start:start + c - 1, fixed] = 1.0 if side in (1, 2) else 0.0
        start += c - 1
    out[:, start:] = inner
    return out

def _pole_corners(tri_uv, collapsed):
    """Corner (u, v) of the triangles that meet at a pole: a corner on a side of its patch that is one point takes,
    along that side, the mean of the triangle's other two corners (as a UV sphere's poles do), so each triangle of a
    fan maps to the thin part of the surface it covers. tri_uv (T, 3, 2); collapsed (T, 4) its patch's sides BOTTOM,
    RIGHT, TOP, LEFT are one point."""
    uv = tri_uv.copy()
    u, v = tri_uv[..., 0], tri_uv[..., 1]
    others_u = (u.sum(axis=1, keepdims=True) - u) / 2
    others_v = (v.sum(axis=1, keepdims=True) - v) / 2
    on_uv = ((u == 1) & collapsed[:, 1:2]) | ((u == 0) & collapsed[:, 3:4])  # RIGHT, LEFT: v runs along them
    on_vv = ((v == 0) & collapsed[:, 0:1]) | ((v == 1) & collapsed[:, 2:3])  # BOTTOM, TOP: u runs along them
    uv[..., 1] = np.where(on_uv & ~on_vv, others_v, v)
    uv[..., 0] = np.where(on_vv & ~on_uv, others_u, u)
    return uv

@lru_cache(maxsize=4096)
def _pattern_uv(key):
    """(u, v) of each local vertex of the pattern of class key (c0, c1, c2, c3, n, m), from its `pattern_codes`:
    corners, side points k / c in each side's direction, inner (i / n, j / m)."""
    codes = pattern_codes(*key)
    kind, a, b = codes[:, 0].astype(int), codes[:, 1].astype(np.float64), codes[:, 2].astype(np.float64)
    c = np.asarray(key[:4], np.float64)
    n, m = float(key[4]), float(key[5])
    t = np.divide(a, c[np.clip(kind - 1, 0, 3)])
    u = np.select([kind == 0, kind == 1, kind == 2, kind == 3, kind == 4], [a, t, 1.0, t, 0.0], a / n)
    v = np.select([kind == 0, kind == 1, kind == 2, kind == 3, kind == 4], [b, 0.0, t, 1.0, t], b / m)
    return np.stack([u, v], 1)

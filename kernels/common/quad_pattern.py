"""The pattern of a quad patch with its own segment count on each side and one inner count (the hardware
tessellator's quad domain with one inner level), welded by construction: an inner grid of ``n - 1`` x ``n - 1``
points, each cell split along its (i, j)-(i+1, j+1) diagonal, and four strips that zip each side's points to the
grid's outer ring (a monotone merge of two parallel rows of points). Inner count 1 with two opposite sides of one
segment is a single strip. Shared by terrain tiles (`kernels.terrain.mesh`) and Bézier surface patches
(`kernels.surfaces.bezier_patches`). Triangles are counter-clockwise in (u, v)."""

from functools import lru_cache

import numpy as np


def _zip(outer, inner):
    """Triangles of the strip between two parallel rows (both listed counter-clockwise around the tile)."""
    p, q = len(outer) - 1, len(inner) - 1
    tris, i, j = [], 0, 0
    while i < p or j < q:
        if j == q or (i < p and (2 * i + 1) * q <= (2 * j + 1) * p):
            tris.append((outer[i], outer[i + 1], inner[j]))
            i += 1
        else:
            tris.append((outer[i], inner[j + 1], inner[j]))
            j += 1
    return tris


@lru_cache(maxsize=4096)
def pattern(c0, c1, c2, c3, n, m=None):
    """Triangles of one tile class in local vertex indices: (k, 3) int32.

    Local vertices: 0..3 corners (0,0) (1,0) (1,1) (0,1); then the interior points of sides BOTTOM, RIGHT,
    TOP, LEFT (``c - 1`` each, in +x or +y order); then the inner grid, row-major, ``(m - 1)`` rows of ``(n - 1)``
    points (n steps along x, m along y; m = n by default). An inner count of 1 is a strip: along x (m = 1) when the
    left and right sides are one segment each, along y (n = 1) when the bottom and top are.
    """
    m = n if m is None else m
    counts = (c0, c1, c2, c3)
    if n == 1 and m == 1 and max(counts) == 1:
        return np.array([(0, 1, 2), (0, 2, 3)], np.int32)
    starts = np.cumsum((4,) + tuple(c - 1 for c in counts))
    side = [list(range(starts[s], starts[s] + counts[s] - 1)) for s in range(4)]
    if m == 1 and c1 == c3 == 1:  # a strip: zip the bottom and top, both in +x order, counter-clockwise from +z
        return np.array(_zip([0] + side[0] + [1], [3] + side[2] + [2]), np.int32)
    if n == 1 and c0 == c2 == 1:
        return np.array(_zip([1] + side[1] + [2], [0] + side[3] + [3]), np.int32)
    rows, ring, grid = strips(c0, c1, c2, c3, n, m)  # grid[j - 1, i - 1]
    tris = [t for s in range(4) for t in _zip(rows[s], ring[s])]
    if m > 2 and n > 2:
        a, b = grid[:-1, :-1].ravel(), grid[:-1, 1:].ravel()
        c, d = grid[1:, 1:].ravel(), grid[1:, :-1].ravel()
        cells = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
        return np.concatenate([np.array(tris, np.int32).reshape(-1, 3), cells.astype(np.int32)])
    return np.array(tris, np.int32)


def pattern_codes(c0, c1, c2, c3, n, m=None):
    """What each local vertex of `pattern` is, for GPU patterns: (L, 3) float32 rows (kind, a, b).

    kind 0: corner at (u, v) = (a, b); kinds 1-4: point ``a`` of side BOTTOM, RIGHT, TOP, LEFT; kind 5: inner
    grid point (i, j) = (a, b). Positions follow from the tile's levels with `partition.point_params`.
    """
    m = n if m is None else m
    rows = [(0, 0, 0), (0, 1, 0), (0, 1, 1), (0, 0, 1)]
    for s, c in enumerate((c0, c1, c2, c3)):
        rows += [(s + 1, k, 0) for k in range(1, c)]
    if n > 1 and m > 1:
        rows += [(5, i, j) for j in range(1, m) for i in range(1, n)]
    return np.array(rows, np.float32)


def strips(c0, c1, c2, c3, n, m=None):
    """The four strips of a tile class whose inner counts are both above 1 (`pattern`'s general case): (rows,
    rings, grid). For each side BOTTOM, RIGHT, TOP, LEFT, the local vertex indices of its points (corners included)
    and of the grid's outer ring beside it, both counter-clockwise around the tile (+x, +y, -x, -y); grid: the inner
    grid's local indices (m - 1, n - 1). `pattern` zips each pair by index; a caller that knows the points'
    parameters may zip them by parameter instead (`zip_by_params`)."""
    m = n if m is None else m
    counts = (c0, c1, c2, c3)
    starts = np.cumsum((4,) + tuple(c - 1 for c in counts))
    side = [list(range(starts[s], starts[s] + counts[s] - 1)) for s in range(4)]
    rows = [[0] + side[0] + [1], [1] + side[1] + [2], [2] + side[2][::-1] + [3], [3] + side[3][::-1] + [0]]
    grid = starts[4] + np.arange((m - 1) * (n - 1)).reshape(m - 1, n - 1)
    ring = [list(grid[0, :]), list(grid[:, -1]), list(grid[-1, ::-1]), list(grid[::-1, 0])]
    return rows, ring, grid


def zip_by_params(outer, inner, t_outer, t_inner):
    """`_zip`'s strip between two rows for many tiles at once, the rows merged by their points' parameters (each
    segment taken in the order of its midpoint's parameter, the outer row's first on a tie) rather than by index.
    outer (p + 1,) and inner (q + 1,) local indices; t_outer (T, p + 1) and t_inner (T, q + 1) increasing
    parameters along the rows. Returns (T, p + q, 3) local indices, counter-clockwise as `_zip`'s."""
    outer, inner = np.asarray(outer), np.asarray(inner)
    mo = 0.5 * (t_outer[:, :-1] + t_outer[:, 1:])
    mi = 0.5 * (t_inner[:, :-1] + t_inner[:, 1:])
    # both rows' midpoints merged by a stable sort (the outer row's first on a tie): an outer step's place in the
    # merge less its index is the inner steps taken before it, and an inner step's the outer steps before it
    order = np.argsort(np.concatenate([mo, mi], axis=1), axis=1, kind="stable")
    place = np.empty_like(order)
    np.put_along_axis(place, order, np.arange(order.shape[1])[None], axis=1)
    p = mo.shape[1]
    j_of_i = place[:, :p] - np.arange(p)[None]  # inner steps taken before outer step i
    i_of_j = place[:, p:] - np.arange(mi.shape[1])[None]  # outer steps taken before inner step j
    out = np.empty((len(mo), p + mi.shape[1], 3), np.result_type(outer, inner))
    out[:, :p, 0], out[:, :p, 1], out[:, :p, 2] = outer[:-1], outer[1:], inner[j_of_i]
    out[:, p:, 0], out[:, p:, 1], out[:, p:, 2] = outer[i_of_j], inner[1:], inner[:-1]
    return out


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
    rows = [[0] + side[0] + [1], [1] + side[1] + [2], [2] + side[2][::-1] + [3], [3] + side[3][::-1] + [0]]
    grid = starts[4] + np.arange((m - 1) * (n - 1)).reshape(m - 1, n - 1)  # grid[j - 1, i - 1]
    ring = [list(grid[0, :]), list(grid[:, -1]), list(grid[-1, ::-1]), list(grid[::-1, 0])]
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

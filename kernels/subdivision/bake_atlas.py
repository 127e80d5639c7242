"""A texture atlas with one cell per triangle, for baking a colour per sub-triangle (the HCE bake).

Triangle ``i`` gets cell ``(i % cells, i // cells)`` of ``cell`` x ``cell`` texels and the right triangle in its
lower-left corner, kept ``margin`` texels from the cell's edges so bilinear filtering and the bake's own spread
never mix two triangles. The colour of a triangle is the mean of the texels whose centres lie inside it.
"""

import numpy as np

from ..common.errors import BudgetError

CELL, MARGIN = 8, 1.0
MAX_RESOLUTION = 16384


def atlas_size(n_triangles, cell=CELL):
    """(cells per row, resolution in texels) for ``n_triangles``; raises `BudgetError` past MAX_RESOLUTION."""
    cells = max(1, int(np.ceil(np.sqrt(n_triangles))))
    res = cells * cell
    if res > MAX_RESOLUTION:
        raise BudgetError(f"{n_triangles:,} sub-triangles need a {res:,}² bake image, over {MAX_RESOLUTION:,}²: "
                          f"bake at a smaller depth")
    return cells, res


def atlas_uvs(n_triangles, cell=CELL, margin=MARGIN):
    """UVs (N, 3, 2) float32 of each triangle's corners in the atlas (0..1), counter-clockwise."""
    cells, _ = atlas_size(n_triangles, cell)
    i = np.arange(n_triangles)
    origin = np.stack([i % cells, i // cells], axis=1).astype(np.float64)
    lo, hi = margin / cell, 1.0 - 2.0 * margin / cell
    corners = np.array([[lo, lo], [hi, lo], [lo, hi]])
    return ((origin[:, None, :] + corners[None]) / cells).astype(np.float32)


def _inside(cell, margin):
    """(cell, cell) bool: texel centres inside the cell's triangle (by a hundredth of a texel at least)."""
    c = (np.arange(cell) + 0.5)[None, :]
    u, v = np.broadcast_arrays(c, c.T)  # u along x (columns), v along y (rows)
    lo, hi = margin, cell - 2.0 * margin
    eps = 0.01
    return (u > lo + eps) & (v > lo + eps) & (u + v < hi + lo - eps)


def triangle_means(pixels, n_triangles, cell=CELL, margin=MARGIN):
    """Mean colour per triangle (N, C) float32 from the baked atlas pixels (res, res, C) (row 0 at v = 0)."""
    cells, res = atlas_size(n_triangles, cell)
    mask = _inside(cell, margin)
    blocks = np.asarray(pixels, np.float64).reshape(cells, cell, cells, cell, -1).transpose(0, 2, 1, 3, 4)
    means = blocks[:, :, mask].mean(axis=2).reshape(cells * cells, -1)  # cell (row, column) = (i // cells, i % cells)
    return means[:n_triangles].astype(np.float32)

"""Atlas dilation: colours spread into the empty texels around each view's outline, never across views."""

import numpy as np
import pytest
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.impostors.dilation import dilate_views


def disk_atlas(grid=3, tile=24, seed=0):
    rng = np.random.default_rng(seed)
    s = grid * tile
    covered = np.zeros((s, s), bool)
    colour = np.zeros((s, s, 3), np.float32)
    yy, xx = np.mgrid[:tile, :tile]
    for j in range(grid):
        for i in range(grid):
            r = rng.uniform(3, 8)
            disk = (yy - tile / 2) ** 2 + (xx - tile / 2) ** 2 < r * r
            covered[j * tile:(j + 1) * tile, i * tile:(i + 1) * tile] = disk
            colour[j * tile:(j + 1) * tile, i * tile:(i + 1) * tile][disk] = rng.uniform(0.1, 1, 3)
    return colour, covered, grid, tile


def manhattan_distance(covered):
    """Texel steps (4-neighbour) to the nearest covered texel, per tile-free image (brute force)."""
    ys, xs = np.nonzero(covered)
    yy, xx = np.mgrid[:covered.shape[0], :covered.shape[1]]
    return np.min(np.abs(yy[..., None] - ys) + np.abs(xx[..., None] - xs), axis=-1)


@pytest.mark.parametrize("steps", [0, 1, 3, 6])
def test_dilation_fills_exactly_the_rings_around_each_view(steps):
    colour, covered, grid, tile = disk_atlas()
    out = dilate_views(colour, covered, grid, steps)
    assert np.array_equal(out[covered], colour[covered])  # what a view rendered is kept
    for j in range(grid):
        for i in range(grid):
            rows, cols = slice(j * tile, (j + 1) * tile), slice(i * tile, (i + 1) * tile)
            cov, src, got = covered[rows, cols], colour[rows, cols], out[rows, cols]
            d = manhattan_distance(cov)
            ring = (d >= 1) & (d <= steps)
            view_colour = src[cov][0]  # one flat colour a view: every filled texel must take it
            assert np.allclose(got[ring], view_colour, atol=1e-6)
            assert np.all(got[d > steps] == 0)  # beyond the rings nothing changed (and nothing came from a neighbour)


def test_views_do_not_bleed_into_each_other():
    colour, covered, grid, tile = disk_atlas(grid=2, tile=16, seed=3)
    covered[:] = False
    colour[:] = 0.0
    covered[:, tile - 1] = True  # a column at the right edge of the left views
    colour[:, tile - 1] = 1.0
    out = dilate_views(colour, covered, grid, 5)
    assert np.all(out[:, tile:] == 0)  # the right views stay empty
    assert np.all(out[:, tile - 6:tile] == 1.0) and np.all(out[:, :tile - 6] == 0)


def test_bad_arguments_are_clear_errors():
    colour, covered, grid, _ = disk_atlas()
    with pytest.raises(InvalidInputError):
        dilate_views(colour, covered, 5, 2)  # 72 texels do not split into 5 views
    with pytest.raises(InvalidInputError):
        dilate_views(colour, covered[:-1], grid, 2)
    with pytest.raises(InvalidInputError):
        dilate_views(colour, covered, grid, -1)

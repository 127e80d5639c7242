"""Octahedral view atlases for baked impostors (the layout of game-engine impostor bakers): a direction d on the
unit sphere maps to uv in [0, 1]² by the octahedral map (full sphere), or by the hemi-octahedral map (upper
hemisphere, z >= 0, for objects seen only from above); an N x N atlas holds one view per cell, taken from the
direction at the cell's centre. `encode` is what a card's material computes from the view direction to pick its
cell (the shader-node graph of `addon.impostors.bake` does the same arithmetic)."""

import numpy as np

from ..common.errors import InvalidInputError


def encode(d, hemi=False):
    """Directions (..., 3) -> uv (..., 2) in [0, 1]."""
    d = np.asarray(d, np.float64)
    if hemi:
        d = np.concatenate([d[..., :2], np.abs(d[..., 2:3])], axis=-1)
    p = d / np.sum(np.abs(d), axis=-1, keepdims=True)
    x, y, z = p[..., 0], p[..., 1], p[..., 2]
    if hemi:  # rotate the diamond |x| + |y| <= 1 onto the square
        u, v = x + y, x - y
    else:
        fold = z < 0
        sx, sy = np.where(x >= 0, 1.0, -1.0), np.where(y >= 0, 1.0, -1.0)
        u = np.where(fold, (1 - np.abs(y)) * sx, x)
        v = np.where(fold, (1 - np.abs(x)) * sy, y)
    return np.stack([u, v], -1) * 0.5 + 0.5


def decode(uv, hemi=False):
    """uv (..., 2) in [0, 1] -> unit directions (..., 3)."""
    uv = np.asarray(uv, np.float64) * 2 - 1
    u, v = uv[..., 0], uv[..., 1]
    if hemi:
        x, y = (u + v) / 2, (u - v) / 2
        z = 1 - np.abs(x) - np.abs(y)
    else:
        x, y = u, v
        z = 1 - np.abs(x) - np.abs(y)
        fold = z < 0
        sx, sy = np.where(x >= 0, 1.0, -1.0), np.where(y >= 0, 1.0, -1.0)
        x, y = np.where(fold, (1 - np.abs(v)) * sx, x), np.where(fold, (1 - np.abs(u)) * sy, y)
    d = np.stack([x, y, z], -1)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def view_directions(grid, hemi=False):
    """The views of an N x N atlas: (N, N, 3) unit directions (from the object towards the camera), cell (i, j)
    (row j, column i; row 0 at v = 0) at its centre."""
    if int(grid) != grid or grid < 1:
        raise InvalidInputError(f"The atlas needs a whole number of views a side; got {grid!r}")
    c = (np.arange(grid) + 0.5) / grid
    u, v = np.meshgrid(c, c)
    return decode(np.stack([u, v], -1), hemi)


def cell_of(d, grid, hemi=False):
    """The atlas cell (i, j) (..., 2) int that shows direction d (..., 3)."""
    uv = encode(d, hemi)
    return np.clip(np.floor(uv * grid), 0, grid - 1).astype(np.int64)

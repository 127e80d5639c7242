"""Dilation of an impostor atlas: each view's colours spread into the empty texels around its outline.

A renderer that filters the atlas (bilinear lookups, mipmaps: every game engine a baked impostor is exported to)
mixes the texels around a lookup; at the outline half of them are empty, and their colour (black) bleeds into the
edge as a dark halo. Dilation gives the empty texels near the outline their neighbours' colours while their alpha
stays 0, so the filtered colour stays the object's and only the filtered alpha fades. Views never bleed into each
other: each tile of the atlas is dilated on its own.
"""

import numpy as np

from ..common.errors import InvalidInputError


def dilate_views(values, covered, grid, steps):
    """Spread the covered texels' values ``steps`` texels into the empty ones, tile by tile.

    values: (S, S, C) float32 atlas channels (S = grid * tile; colour without alpha, or normals); covered: (S, S)
    bool, the texels a view rendered; grid: views a side; steps: rings of texels to fill (0: none). Each pass gives
    every empty texel with covered 4-neighbours in its own tile the mean of their values and counts it as covered
    for the next pass. Returns (S, S, C) float32 (a new array; covered texels unchanged).
    """
    values = np.asarray(values, np.float32)
    covered = np.asarray(covered, bool)
    s = values.shape[0]
    if values.ndim != 3 or values.shape[:2] != (s, s) or covered.shape != (s, s):
        raise InvalidInputError(f"Atlas channels must be (S, S, C) with an (S, S) coverage; got {values.shape} and "
                                f"{covered.shape}")
    if grid < 1 or s % grid:
        raise InvalidInputError(f"An atlas of {s} texels does not split into {grid} views a side")
    if steps < 0:
        raise InvalidInputError(f"Dilation must be 0 or more texels; got {steps}")
    tile, c = s // grid, values.shape[2]
    # (view row, texel row, view column, texel column, channel): shifting the texel axes never crosses a view
    out = values.reshape(grid, tile, grid, tile, c).copy()
    done = covered.reshape(grid, tile, grid, tile).copy()
    for _ in range(steps):
        total = np.zeros_like(out)
        count = np.zeros(done.shape, np.float32)
        for axis in (1, 3):
            for shift in (1, -1):
                src = [slice(None)] * 4
                dst = [slice(None)] * 4
                src[axis] = slice(None, -1) if shift == 1 else slice(1, None)
                dst[axis] = slice(1, None) if shift == 1 else slice(None, -1)
                src, dst = tuple(src), tuple(dst)
                filled = done[src]
                total[dst] += np.where(filled[..., None], out[src], 0.0)
                count[dst] += filled
        grow = ~done & (count > 0)
        if not grow.any():
            break
        out[grow] = total[grow] / count[grow][:, None]
        done |= grow
    return out.reshape(s, s, c)

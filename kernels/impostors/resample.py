"""A rendered board resampled to another resolution ([Clua et al., §5]: a cached board "reused or resampled").

A board finer than the eye needs (the camera moved away) is still valid, but every frame pre-warps all its texels;
resampled to what eq. 8 asks for, it costs what a board rendered for this distance would. Each output texel is the
box-filter (area) average of the input texels it covers, for any ratio: exact area sums from running sums along each
axis, interpolated linearly inside a texel (O(n²), no (n_out, n_in) matrices). Coverage decides the outline: an output
texel is present where at least half of its area was; its colour is the alpha-weighted mean (straight alpha out), its
displacement and normal the means over the present texels it covers (the normal made unit again). The board keeps
its place and extent: the same origin, texel axes scaled by the ratio.
"""

from dataclasses import replace

import numpy as np

from ..common.errors import InvalidInputError
from ..common.tolerances import NO_DIRECTION
from .prewarp import ReliefFrame


def box_mean(image, n_out):
    """Area means of ``image`` (n, n, ...) over an n_out x n_out grid covering the same square: (n_out, n_out, ...)
    float64."""
    out = np.asarray(image, np.float64)
    for axis in (0, 1):
        out = _box_axis(out, n_out, axis)
    return out


def _box_axis(a, n_out, axis):
    a = np.moveaxis(a, axis, 0)
    n = len(a)
    running = np.concatenate([np.zeros((1,) + a.shape[1:]), np.cumsum(a, axis=0)])  # (n + 1, ...)
    x = np.arange(n_out + 1) * (n / n_out)
    i = np.minimum(np.floor(x).astype(np.int64), n - 1)
    frac = (x - i).reshape((-1,) + (1,) * (a.ndim - 1))
    area = running[i] + frac * a[i]  # the sum of the input over [0, x)
    return np.moveaxis((area[1:] - area[:-1]) * (n_out / n), 0, axis)


def resample_board(setup, colours, displacement, normals, present, resolution):
    """The board at ``resolution`` texels a side.

    setup: its `board.BoardSetup`; colours (n, n, 4) straight alpha, displacement (n, n), normals (n, n, 3), present
    (n, n) bool. Returns ``(setup, colours, displacement, normals, present)`` of the same types at the new resolution
    (colours and normals float32, displacement float64).
    """
    n = int(setup.resolution)
    resolution = int(resolution)
    if colours.shape[:2] != (n, n) or displacement.shape != (n, n) or present.shape != (n, n):
        raise InvalidInputError(f"The board's images are not {n} x {n} texels")
    if resolution < 1:
        raise InvalidInputError("A board needs at least one texel a side")
    alpha = colours[..., 3].astype(np.float64)
    mask = present.astype(np.float64)
    coverage = box_mean(mask, resolution)
    out_present = coverage >= 0.5
    out_alpha = box_mean(alpha, resolution)
    premultiplied = box_mean(colours[..., :3] * alpha[..., None], resolution)
    out_colours = np.concatenate([premultiplied / np.maximum(out_alpha, NO_DIRECTION)[..., None],
                                  out_alpha[..., None]], -1)
    weight = np.maximum(coverage, NO_DIRECTION)
    out_d = np.where(out_present, box_mean(displacement * mask, resolution) / weight, 0.0)
    out_n = box_mean(normals * mask[..., None], resolution)
    out_n /= np.maximum(np.linalg.norm(out_n, axis=-1, keepdims=True), NO_DIRECTION)
    scale = n / resolution
    frame = setup.frame
    new_setup = replace(setup, frame=ReliefFrame(frame.origin, frame.a * scale, frame.b * scale, frame.f),
                        resolution=resolution)
    return new_setup, out_colours.astype(np.float32), out_d, out_n.astype(np.float32), out_present

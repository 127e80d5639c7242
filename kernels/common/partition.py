"""Tessellation levels -> segment counts and the parameters of the points along an edge.

Two spacings, in the style of the OpenGL / D3D11 fixed-function tessellator:

``EQUAL``
    The level is clamped to ``[1, MAX_LEVEL]`` and rounded up: ``n = ceil(level)`` equal segments.
``FRACTIONAL_EVEN``
    The level ``f`` is clamped to ``[2, MAX_LEVEL]`` and ``n`` is the smallest even integer ``>= f``.
    When ``f == n`` the segments are equal; otherwise there are ``n - 2`` equal long segments and two
    equal short ones of length ``(f - (n - 2)) / (2 n)`` placed either side of the edge midpoint. The
    short segments grow continuously from zero as ``f`` rises, so vertices slide instead of popping.
    Like the hardware mode, a fractional-even edge always has at least two segments.

The layout of the points is a palindrome: point ``j`` of ``n`` is computed for ``j <= n/2`` and
mirrored (``1 - t``) above, so an edge looks the same from either end. Callers that need bit-identical
points on a shared edge evaluate it in one canonical direction (lower vertex index first).
"""

import numpy as np

from .errors import InvalidInputError

MAX_LEVEL = 64
SPACINGS = ("EQUAL", "FRACTIONAL_EVEN")


def _check_spacing(spacing):
    if spacing not in SPACINGS:
        raise InvalidInputError(f"Unknown spacing {spacing!r}; expected one of {', '.join(SPACINGS)}")


def clamp_levels(levels, spacing="EQUAL"):
    """Clamp levels to the spacing's valid range.

    levels: (...) float, finite. Returns (...) float64.
    """
    _check_spacing(spacing)
    f = np.asarray(levels, dtype=np.float64)
    if not np.all(np.isfinite(f)):
        raise InvalidInputError("Tessellation levels must be finite numbers (found NaN or infinity)")
    low = 1.0 if spacing == "EQUAL" else 2.0
    return np.clip(f, low, MAX_LEVEL)


def segment_counts(levels, spacing="EQUAL"):
    """Number of segments for each level.

    levels: (...) float. Returns (...) int32 in ``[1, MAX_LEVEL]`` (``[2, MAX_LEVEL]``, even, for FRACTIONAL_EVEN).
    """
    f = clamp_levels(levels, spacing)
    if spacing == "EQUAL":
        n = np.ceil(f)
    else:
        n = 2.0 * np.ceil(f / 2.0)
    return n.astype(np.int32)


def point_params(levels, counts, index, spacing="EQUAL"):
    """Parameter in [0, 1] of point ``index`` on an edge of ``counts`` segments at clamped ``levels``.

    levels: (k,) float64 clamped levels (see `clamp_levels`); counts: (k,) int, from `segment_counts`;
    index: (k,) int in ``[0, counts]``. Returns (k,) float64; ``index == 0`` gives 0 and ``index == counts`` 1.
    """
    f = np.asarray(levels, dtype=np.float64)
    n = np.asarray(counts, dtype=np.int64)
    j = np.asarray(index, dtype=np.int64)
    jm = np.minimum(j, n - j)  # distance from the nearer end, in points
    if spacing == "EQUAL":
        half = jm / n
    else:
        _check_spacing(spacing)
        nf = n.astype(np.float64)
        with np.errstate(divide="ignore", invalid="ignore"):
            long_len = np.where(n > 2, (2.0 * nf - 2.0 - f) / (nf * (nf - 2.0)), 0.5)
        half = np.where(2 * jm == n, 0.5, jm * long_len)
    return np.where(2 * j <= n, half, 1.0 - half)

"""Level metrics every capability shares ([Nellmedin 2014, ch. 4]): the camera-distance map (eqs. 4.1-4.3), the
projected size of a sphere (§4.4, the projected-edge metric's core) and the curvature of control polygons (§4.3, eqs.
4.4 and 4.5; scale-invariant: scaling a control polygon leaves its κ⁺ unchanged). Used by the curved triangle patches
(`kernels.tessellation.adaptive`), the adaptive curves and the Bézier surface patches."""

import numpy as np

from .errors import InvalidInputError

DISTANCE_MAPS = ("LINEAR", "INVERSE")


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def curve_kappa(control):
    """Eq. 4.4: the largest ``|p_i - (p_{i-1} + p_{i+1}) / 2| / |p_{i+1} - p_{i-1}|`` over interior points.

    control: (..., n, d) control polygons, n >= 3. Degenerate chords (zero denominator) count as the
    cap (``inf``) when the numerator is non-zero, 0 otherwise ([Nellmedin 2014, correction 4]). Returns (...).
    """
    c = np.asarray(control, np.float64)
    if c.shape[-2] < 3:
        return np.zeros(c.shape[:-2])
    num = c[..., 1:-1, :] - 0.5 * (c[..., :-2, :] + c[..., 2:, :])
    den = c[..., 2:, :] - c[..., :-2, :]
    num, den = np.sqrt(_dot(num, num)), np.sqrt(_dot(den, den))
    kappa = np.divide(num, den, out=np.where(num > 0, np.inf, 0.0), where=den > 0)
    return kappa.max(axis=-1)


def curvature_level(kappa, n_control=4, gain=10.0, t_max=32.0, minimum=None):
    """Eq. 4.5: ``max(minimum, min(t_max, gain * kappa))``; ``minimum`` defaults to ``2 (n - 1)``."""
    low = 2.0 * (n_control - 1) if minimum is None else float(minimum)
    return np.maximum(low, np.minimum(t_max, gain * np.asarray(kappa, np.float64)))


def distance_level(d, d_min, d_max, t_max, mapping="LINEAR"):
    """Camera-distance level (Eqs. 4.1-4.3), clamped to ``[1, t_max]``.

    d: (...) distances. ``LINEAR``: ``t_max`` at ``d_min`` falling linearly to 1 at ``d_max``. ``INVERSE``:
    the z-buffer-like ``A/d + B`` through the same two points (more levels near the camera).
    """
    if not d_max > d_min > 0 and mapping == "INVERSE":
        raise InvalidInputError("The inverse distance map needs 0 < near distance < far distance")
    if not d_max > d_min:
        raise InvalidInputError("The far distance must be larger than the near distance")
    d = np.asarray(d, dtype=np.float64)
    if mapping == "LINEAR":
        t = 1.0 + (t_max - 1.0) * (d_max - d) / (d_max - d_min)
    elif mapping == "INVERSE":
        a = (t_max - 1.0) * d_max * d_min / (d_max - d_min)
        b = (d_max - t_max * d_min) / (d_max - d_min)
        with np.errstate(divide="ignore"):
            t = np.where(d > 0, a / np.maximum(d, np.finfo(np.float64).tiny) + b, t_max)
    else:
        raise InvalidInputError(f"Unknown distance map {mapping!r}; expected one of {', '.join(DISTANCE_MAPS)}")
    return np.clip(t, 1.0, t_max)


def projected_sphere_levels(m, d, projection, height, e_max, t_max):
    """Pixels a sphere of diameter ``d`` at eye-space point ``m`` spans on screen, over ``e_max`` ([Nellmedin 2014,
    §4.4], corrected): ``m`` and ``m + (0, d, 0)`` are projected, so the result does not depend on which way the
    measured thing points. m: (..., 3) eye space (looking down -z); d: (...); projection: (4, 4) row-major; height:
    viewport height in pixels. A sphere reaching behind the eye plane gets ``t_max``; one entirely behind gets 1.
    Returns (...) float64 in ``[1, t_max]``."""
    if e_max <= 0:
        raise InvalidInputError("The target edge length in pixels must be positive")
    m = np.asarray(m, np.float64)
    d = np.asarray(d, np.float64)
    proj = np.asarray(projection, np.float64)

    def ndc_y(x, y, z):
        clip_y = proj[1, 0] * x + proj[1, 1] * y + proj[1, 2] * z + proj[1, 3]
        clip_w = proj[3, 0] * x + proj[3, 1] * y + proj[3, 2] * z + proj[3, 3]
        return clip_y, clip_w

    y0, w0 = ndc_y(m[..., 0], m[..., 1], m[..., 2])
    y1, w1 = ndc_y(m[..., 0], m[..., 1] + d, m[..., 2])
    ahead = (w0 > 0) & (w1 > 0)
    safe0, safe1 = np.where(ahead, w0, 1.0), np.where(ahead, w1, 1.0)
    pixels = np.abs(y1 / safe1 - y0 / safe0) * (height * 0.5)
    t = np.where(ahead, pixels / e_max, 1.0)
    crosses = m[..., 2] + 0.5 * d > 0
    t = np.where(crosses & (m[..., 2] - 0.5 * d < 0), t_max, t)
    return np.clip(t, 1.0, t_max)

"""The curvature metric of control polygons (digest 001 §4.3, eqs. 4.4 and 4.5): shared by the curved triangle
patches (`kernels.tessellation.adaptive`), the adaptive curves and the Bézier surface patches. Scale-invariant:
scaling a control polygon leaves its κ⁺ unchanged."""

import numpy as np


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def curve_kappa(control):
    """Eq. 4.4: the largest ``|p_i - (p_{i-1} + p_{i+1}) / 2| / |p_{i+1} - p_{i-1}|`` over interior points.

    control: (..., n, d) control polygons, n >= 3. Degenerate chords (zero denominator) count as the
    cap (``inf``) when the numerator is non-zero, 0 otherwise (digest 001 §10 item 5). Returns (...).
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

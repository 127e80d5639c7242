"""Rational Bézier curves of any degree in homogeneous coordinates ``(w x, w y, w z, w)``: the Bernstein basis and its
derivative, points, and how far a curve strays from its chords — what the NURBS surfaces and curves share to meet a
chordal tolerance ([Piegl 1997, ch. 1 and 4]).

The chord of a short step ``h`` of a smooth curve strays at most about ``h² max|C''| / 8`` from it, largest near the
step's middle: the deviation measured at ``m`` equal steps falls with the square of the step, so ``n = m
sqrt(deviation / tolerance)`` steps meet a tolerance (`steps_for`). The estimate is then checked on the steps chosen
(`chord_deviation` at each step's quarter points) and raised where it is still over.
"""

from math import comb

import numpy as np

from . import step_spacing

#: Step counts from a tolerance aim this far under it, so a deviation between the measured points stays under.
TOLERANCE_AIM = 0.8


def bernstein(t, degree=3):
    """Bernstein basis of a degree (..., degree + 1) at t (...)."""
    t = np.asarray(t, np.float64)
    s = 1.0 - t
    tp = np.empty(t.shape + (degree + 1,))
    sp = np.empty_like(tp)
    tp[..., 0] = sp[..., 0] = 1.0
    for i in range(1, degree + 1):  # powers by products: no pow calls
        tp[..., i] = tp[..., i - 1] * t
        sp[..., i] = sp[..., i - 1] * s
    coef = np.array([comb(degree, i) for i in range(degree + 1)], np.float64)
    return coef * tp * sp[..., ::-1]


def bernstein_derivative(t, degree=3):
    """d/dt of the Bernstein basis (..., degree + 1) at t (...)."""
    if degree == 0:
        return np.zeros(np.shape(t) + (1,))
    b = bernstein(t, degree - 1)
    zero = np.zeros(b.shape[:-1] + (1,))
    return degree * (np.concatenate([zero, b], -1) - np.concatenate([b, zero], -1))


def cartesian(h):
    """Cartesian positions (..., 3) of homogeneous points (..., 4 or more: w is column 3)."""
    h = np.asarray(h, np.float64)
    return h[..., :3] / h[..., 3:4]


def curve_points(h, t):
    """Homogeneous points (S, n, d) of rational curves h (S, k, d) at t (n,) or (S, n)."""
    h = np.asarray(h, np.float64)
    b = bernstein(t, h.shape[1] - 1)
    if b.ndim == 2:
        b = np.broadcast_to(b, (len(h),) + b.shape)
    return np.matmul(b, h)


def steps_for(deviation, steps, tolerance, most):
    """Steps so a deviation measured at ``steps`` equal steps falls under the aimed tolerance (quadratic in the step):
    deviation and steps (S,) or scalars -> (S,) int64 in [1, most]."""
    want = steps * np.sqrt(np.maximum(deviation, 0.0) / (TOLERANCE_AIM * tolerance))
    return np.clip(np.ceil(want), 1, most).astype(np.int64)


def chord_deviation(control, steps, spacing=None):
    """The largest distance between each rational curve and its chords at ``steps`` steps of its parameter,
    measured at each chord's quarter points: control (S, k, 4) homogeneous, steps (S,) -> (S,) float64. The steps
    are equal, or spaced by each curve's table spacing (S, M + 1) (`kernels.common.curves.step_spacing`)."""
    h = np.asarray(control, np.float64)[..., :4]
    lv = np.broadcast_to(np.asarray(steps, np.int64), (len(h),))
    out = np.zeros(len(h))
    frac = np.array([0.25, 0.5, 0.75])
    for n in np.unique(lv):
        es = np.flatnonzero(lv == n)
        if spacing is None:
            t = np.arange(n + 1) / n
            at = (t[:-1, None] + frac[None] / n).ravel()
        else:
            t = step_spacing.params(spacing[es], int(n))
            at = (t[:, :-1, None] + frac[None, None] * np.diff(t, axis=1)[..., None]).reshape(len(es), -1)
        ends = cartesian(curve_points(h[es], t))
        mid = cartesian(curve_points(h[es], at)).reshape(len(es), n, 3, 3)
        chord = ends[:, :-1, None] + frac[None, None, :, None] * (ends[:, 1:, None] - ends[:, :-1, None])
        out[es] = np.linalg.norm(mid - chord, axis=-1).reshape(len(es), -1).max(axis=1)
    return out


def tolerance_steps(control, tolerance, most, rounds=8, spacing=None):
    """Steps per curve so its chords stay within ``tolerance`` (a number or (S,)): estimated at 16 steps, then
    checked and raised. control (S, k, 4) homogeneous; spacing (S, M + 1): the steps where each curve bends
    (`curve_spacing`), or None for equal steps. Returns (steps (S,) int64 in [1, most], deviation (S,) at those
    steps)."""
    h = np.asarray(control, np.float64)
    tol = np.broadcast_to(np.asarray(tolerance, np.float64), (len(h),))
    steps = steps_for(chord_deviation(h, 16, spacing), 16, tol, most)
    for _ in range(rounds):
        dev = chord_deviation(h, steps, spacing)
        over = (dev > tol) & (steps < most)
        if not over.any():
            return steps, dev
        steps = np.where(over, np.minimum(most, np.maximum(steps + 1, steps_for(dev, steps, tol, most))), steps)
    return steps, chord_deviation(h, steps, spacing)


def curve_spacing(control):
    """Spacing tables (S, SAMPLES + 1) (`kernels.common.curves.step_spacing`) of rational curves with homogeneous
    control points (S, k, 4): their steps where they bend."""
    t = np.linspace(0.0, 1.0, 2 * step_spacing.SAMPLES + 1)
    return step_spacing.cumulative(step_spacing.bend_density(cartesian(curve_points(control, t))))

"""Steps spaced where a curve bends (`kernels.common.curves.step_spacing`): tables from 0 to 1, steps within
1 / FLOOR of each other, equal steps where nothing bends, chord deviations evened out, and NURBS curves meeting a
tolerance with fewer points than equal steps need (measured independently, at 64 points a step)."""

import numpy as np
from tessera.kernels.common.curves import nurbs
from tessera.kernels.common.curves import rational_bezier as rb
from tessera.kernels.common.curves import step_spacing as ss


def test_steps_run_from_zero_to_one_within_the_floor_of_each_other():
    rng = np.random.default_rng(3)
    density = rng.random((50, ss.SAMPLES)) ** 4 * rng.uniform(0, 10, (50, 1))
    cum = ss.cumulative(density)
    assert (cum[:, 0] == 0).all() and (cum[:, -1] == 1).all() and (np.diff(cum, axis=1) > 0).all()
    for n in (1, 2, 7, 64):
        t = ss.params(cum, n)
        assert (t[:, 0] == 0).all() and (t[:, -1] == 1).all()
        step = np.diff(t, axis=1)
        assert (step > 0).all()
        assert (step.max(axis=1) / step.min(axis=1) <= 1 / ss.FLOOR * (1 + 1e-9)).all()
    # nothing bends: equal steps
    flat = ss.params(ss.cumulative(np.zeros((2, ss.SAMPLES))), 10)
    assert np.abs(flat - np.arange(11) / 10).max() < 1e-15
    padded = ss.padded_params(cum[:3], np.array([2, 5, 3]))
    assert padded.shape == (3, 6) and np.array_equal(padded[0, 2:], np.ones(4))
    assert np.array_equal(padded[1], ss.params(cum[1:2], 5)[0])


def _pieces(rng, order=4, count=8):
    pts = np.c_[rng.normal(size=(count, 3)), rng.uniform(0.3, 2.0, count)]
    pieces, _ = nurbs.curve_pieces(pts, nurbs.Direction(order, "ENDPOINT", False), np.zeros((count, 2)))
    return pieces[..., :4]


def _dense_deviation(h, t):
    """The largest distance between one rational curve h (k, 4) and the polyline through its points at t (n + 1,),
    at 64 points of each step: (n,) per step."""
    ends = rb.cartesian(rb.curve_points(h[None], t[None]))[0]
    f = (np.arange(1, 64) / 64)[None]
    at = t[:-1, None] + f * np.diff(t)[:, None]
    on = rb.cartesian(rb.curve_points(h[None], at.reshape(1, -1)))[0].reshape(len(t) - 1, -1, 3)
    chord = ends[:-1, None] + f[..., None] * (ends[1:, None] - ends[:-1, None])
    return np.linalg.norm(on - chord, axis=-1).max(axis=1)


def test_steps_where_a_curve_bends_even_out_its_chords():
    # one cubic that is nearly straight but for a sharp bend near its end
    h = np.array([[[0, 0, 0, 1], [1, 0, 0, 1], [2, 0, 0, 1], [2, 1, 0, 1]]], np.float64)
    cum = rb.curve_spacing(h)
    equal, spaced = np.arange(17) / 16, ss.params(cum, 16)[0]
    d_equal, d_spaced = _dense_deviation(h[0], equal), _dense_deviation(h[0], spaced)
    assert d_spaced.max() < 0.5 * d_equal.max()
    assert d_spaced.max() / d_spaced.min() < d_equal.max() / d_equal.min()
    assert np.diff(spaced)[-1] < np.diff(spaced)[0]  # short steps where it bends


def test_nurbs_curves_meet_the_tolerance_with_fewer_spaced_points():
    rng = np.random.default_rng(11)
    tol, points_equal, points_spaced = 1e-3, 0, 0
    for _ in range(12):
        geo = _pieces(rng)
        equal, _ = rb.tolerance_steps(geo, tol, 4096)
        cum = rb.curve_spacing(geo)
        spaced, dev = rb.tolerance_steps(geo, tol, 4096, spacing=cum)
        assert (dev <= tol).all()
        for h, table, n in zip(geo, cum, spaced, strict=True):  # measured again, densely: within the tolerance
            assert _dense_deviation(h, ss.params(table[None], int(n))[0]).max() <= tol
        points_equal += int(equal.sum())
        points_spaced += int(spaced.sum())
    assert points_spaced < 0.8 * points_equal

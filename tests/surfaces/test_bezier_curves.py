"""Cubic Bézier splines sampled where they bend ([Nellmedin 2014, §4.3 eq. 4.5, §5.5.2])."""

import numpy as np
import pytest
from tessera.kernels.common import camera
from tessera.kernels.common.curves import bezier_curves as bz
from tessera.kernels.common.errors import InvalidInputError


def poly3(*pts):
    """A 2-D control polygon as (1, 4, 3)."""
    return np.array([[[x, y, 0.0] for x, y in pts]])


@pytest.mark.parametrize("control,segments", [
    (((0, 0), (1, 0), (2, 0), (3, 0)), 6),        # straight: the minimum 2 (n - 1)
    (((0, 0), (0, 1), (1, 1), (1, 0)), 6),        # κ 0.5 -> 5, raised to 6
    (((0, 0), (1, 4), (2, 0), (3, 0)), 20),       # κ 2
    (((0, 0), (7, 28), (14, 0), (21, 0)), 20),    # the same x 7: scale-invariant
    (((0, 0), (1, 10), (2, 0), (3, 0)), 32),      # κ 5 -> capped
])
def test_curvature_counts_follow_eq_4_5(control, segments):
    assert bz.curvature_counts(poly3(*control))[0] == segments


def test_near_straight_gets_6_sharp_bend_up_to_32():
    rng = np.random.default_rng(0)
    straight = poly3((0, 0), (1, 0.01), (2, -0.01), (3, 0))
    assert bz.curvature_counts(straight)[0] == 6
    bends = np.array([poly3((0, 0), (1, h), (2, 0), (3, 0))[0] for h in rng.uniform(0, 20, 50)])
    counts = bz.curvature_counts(bends)
    assert counts.min() >= 6 and counts.max() == 32


@pytest.mark.parametrize("cyclic", [False, True])
def test_samples_lie_on_the_curve_and_share_ends(cyclic):
    rng = np.random.default_rng(1)
    co = rng.normal(size=(5, 3))
    hl, hr = co + rng.normal(scale=0.4, size=(5, 3)), co + rng.normal(scale=0.4, size=(5, 3))
    control = bz.segment_controls(co, hl, hr, cyclic)
    assert len(control) == (5 if cyclic else 4)
    counts = bz.curvature_counts(control)
    s = bz.sample(control, counts, cyclic)
    assert len(s.points) == counts.sum() + (0 if cyclic else 1)
    # every sample is the Bernstein cubic of its segment at its t, and control points are hit exactly
    for p, seg, t in zip(s.points, s.segment, s.t, strict=True):
        b = control[seg]
        want = (1 - t) ** 3 * b[0] + 3 * (1 - t) ** 2 * t * b[1] + 3 * (1 - t) * t * t * b[2] + t ** 3 * b[3]
        assert np.allclose(p, want, atol=1e-12)
    starts = np.cumsum(counts) - counts
    assert np.array_equal(s.points[starts], co[: len(control)])  # each segment starts on its control point
    assert np.all(np.diff(s.t[s.segment == 0]) > 0)


def test_tolerance_bounds_the_error():
    rng = np.random.default_rng(2)
    control = rng.normal(size=(30, 4, 3))
    for tol in (0.1, 0.01, 0.001):
        counts = bz.tolerance_counts(control, tol)
        s = bz.sample(control, counts, cyclic=False)
        # the polyline's distance to the curve, checked densely between samples: within tol
        for i in range(len(control)):
            rows = np.flatnonzero(s.segment == i)
            pts = np.vstack([s.points[rows], control[i, 3]])
            t = np.linspace(0, 1, 400)
            dense = bz.evaluate(control[i:i + 1], t[None])[0]
            step = np.minimum((t * counts[i]).astype(int), counts[i] - 1)
            a, b = pts[step], pts[step + 1]
            u = (t * counts[i] - step)[:, None]
            assert np.linalg.norm(dense - (a + u * (b - a)), axis=1).max() <= tol * (1 + 1e-9)
    with pytest.raises(InvalidInputError):
        bz.tolerance_counts(control, 0.0)


def test_pixel_tolerance_follows_depth():
    cam = camera.Camera(camera.look_at_view((0, -10, 0), (0, 0, 0)), camera.perspective(0.8, 1.0, 0.1, 1e3), 400, 400)
    near = poly3((0, 0), (1, 1), (2, 0), (3, 0)) - [0, 5, 0]
    far = poly3((0, 0), (1, 1), (2, 0), (3, 0)) + [0, 90, 0]
    tol = bz.pixel_tolerance(np.concatenate([near, far]), cam, 1.0)
    assert tol[1] > 10 * tol[0]
    counts = bz.tolerance_counts(np.concatenate([near, far]), tol)
    assert counts[0] > counts[1]


def test_six_offset_copies():
    pts = bz.sample(poly3((0, 0), (1, 3), (2, -3), (3, 0)), [8], False).points
    copies = bz.offset_copies(pts, 6, (0.0, 0.0, 1.2))
    assert copies.shape == (6, 9, 3)
    assert np.array_equal(copies[0], pts)
    assert np.allclose(copies[5] - pts, [0, 0, 1.0])
    with pytest.raises(InvalidInputError):
        bz.offset_copies(pts, 0, (0, 0, 1))


def test_adaptive_spline_interpolates_radius_and_tilt_and_copies():
    from tessera.kernels.common.curves.bezier_curves import CurveSampling, adaptive_spline

    co = np.array([[0, 0, 0], [3, 0, 0], [3, 3, 0.5]], float)
    hl, hr = co - [0.5, 1, 0], co + [0.5, 1, 0]
    out = adaptive_spline(co, hl, hr, [1.0, 2.0, 3.0], [0.0, 0.5, 1.0], False, CurveSampling(copies=3,
                                                                                              offset=(0, 0, 3)))
    assert len(out) == 3 and np.allclose(out[2].points - out[0].points, [0, 0, 2])
    a = out[0]
    first = a.counts[0]
    assert a.radius[0] == 1.0 and a.radius[first] == 2.0 and a.radius[-1] == 3.0
    assert np.all(np.diff(a.radius) > 0) and np.allclose(a.tilt, (a.radius - 1) / 2)
    with pytest.raises(InvalidInputError):
        adaptive_spline(co, hl, hr, [1, 1, 1], [0, 0, 0], False, CurveSampling(mode="SCREEN"))
    with pytest.raises(InvalidInputError):
        CurveSampling(mode="FAST")

"""The relief-texture pre-warp ([Clua et al.], eq. 7; [Oliveira 2000]): eq. 7 in the corrected convention
against ray-plane intersection, the parallel guard, the epipole and the occlusion-compatible order (the collision
case, and agreement with a depth-buffered splat), the offset map."""

import numpy as np
import pytest
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.impostors import prewarp as pw


def random_frame(rng):
    a = rng.normal(size=3)
    b = rng.normal(size=3)
    f = np.cross(a, b)
    f /= np.linalg.norm(f)
    return pw.ReliefFrame(rng.normal(size=3), a * rng.uniform(0.5, 2), b * rng.uniform(0.5, 2), f)


def test_eq_7_is_the_ray_plane_intersection():
    rng = np.random.default_rng(0)
    for _ in range(50):
        frame = random_frame(rng)
        eye = rng.normal(scale=8, size=3)
        k = pw.prewarp_constants(frame, eye)  # once per centre of projection
        u, v, d = rng.uniform(-5, 5, 200), rng.uniform(-5, 5, 200), rng.uniform(-1, 1, 200)
        ui, vi, valid = pw.prewarp(u, v, d, k)
        ru, rv = pw.ray_plane_reference(frame, eye, u, v, d)
        ok = valid & (np.abs(1 + k[2] * d) > 1e-3)  # away from the parallel guard the 3 x 3 solve is well posed
        assert np.abs(ui[ok] - ru[ok]).max() <= 1e-9 * (1 + np.abs(ru[ok]).max())
        assert np.abs(vi[ok] - rv[ok]).max() <= 1e-9 * (1 + np.abs(rv[ok]).max())


def test_the_parallel_guard():
    """C_d level with a displaced texel: 1 + k3 d = 0, marked invalid, no division."""
    frame = pw.ReliefFrame(np.zeros(3), np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0, 0, 1.0]))
    eye = np.array([0.3, 0.2, 2.0])
    k = pw.prewarp_constants(frame, eye)
    assert k[2] == pytest.approx(-0.5)
    ui, vi, valid = pw.prewarp([1.0, 1.0], [1.0, 1.0], [2.0, 1.0], k)
    assert list(valid) == [False, True] and np.isnan(ui[0]) and np.isfinite(ui[1])
    with pytest.raises(InvalidInputError):
        pw.prewarp_constants(frame, np.array([3.0, 4.0, 0.0]))  # the eye in the source plane


def test_the_collision_keeps_the_higher_texel():
    """The collision case of [Clua et al., correction 2]: source plane z = 0, C_d at height h in front: (u = 1, d = h/2)
    and (u = 2, d = 0) both land on u_i = 2; the higher one, nearer C_d, must win."""
    h = 4.0
    frame = pw.ReliefFrame(np.zeros(3), np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0, 0, 1.0]))
    eye = np.array([0.0, 0.0, h])
    k = pw.prewarp_constants(frame, eye)
    assert k[0] == 0 and k[2] == pytest.approx(-1 / h)
    ui, _, _ = pw.prewarp([1.0, 2.0], [0.0, 0.0], [h / 2, 0.0], k)
    assert ui == pytest.approx([2.0, 2.0])
    assert pw.epipole(frame, eye) == pytest.approx((0.0, 0.0, h))
    # the same on a texel grid: texels 8 and 16 of a row meet at 16; the painter keeps the raised one
    d = np.zeros((4, 40))
    d[:, 8] = h / 2
    frame_px = pw.ReliefFrame(np.array([-0.5, -0.5, 0.0]), frame.a, frame.b, frame.f)  # texel centres at integers
    splat = pw.forward_splat(d, frame_px, eye)
    src = splat.source[0, 16]
    assert src % 40 == 8
    assert np.array_equal(pw.zbuffer_splat(d, frame_px, eye).source[0, 16], src)


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_painting_order_matches_a_depth_buffer(side):
    """Smooth random height fields seen from random eyes in front of the plane and behind it (edges -> epipole on
    both sides: a parallel source has its centre of projection at infinity): the painter's result equals the
    depth-buffered splat wherever both painted (pixel rounding may swap a few)."""
    rng = np.random.default_rng(2 if side > 0 else 3)
    w = h = 48
    y, x = np.mgrid[0:h, 0:w] / w
    frame = pw.ReliefFrame(np.array([-0.5, -0.5, 0.0]) * 0.1, np.array([0.1, 0, 0]), np.array([0, 0.1, 0]),
                           np.array([0, 0, 1.0]))
    for _ in range(5):
        d = 0.4 + 0.4 * np.sin(rng.uniform(2, 6) * x + rng.uniform(0, 6)) * np.cos(rng.uniform(2, 6) * y)
        eye = np.array([rng.uniform(-2, 6), rng.uniform(-2, 6), side * rng.uniform(3, 8)])
        painted, oracle = pw.forward_splat(d, frame, eye), pw.zbuffer_splat(d, frame, eye)
        both = (painted.source >= 0) & (oracle.source >= 0)
        assert np.array_equal(painted.source >= 0, oracle.source >= 0)
        assert both.sum() > 0.3 * w * h
        assert np.mean(painted.source[both] == oracle.source[both]) >= 0.99


def test_the_offset_map_addresses_the_source():
    rng = np.random.default_rng(5)
    d = rng.uniform(0, 0.2, (16, 16))
    frame = pw.ReliefFrame(np.zeros(3), np.array([0.1, 0, 0]), np.array([0, 0.1, 0]), np.array([0, 0, 1.0]))
    splat = pw.forward_splat(d, frame, np.array([0.9, 0.7, 3.0]))
    colours = rng.random((16, 16, 3))
    out = splat.gather(colours)
    offs = splat.offsets
    filled = splat.source >= 0
    iu, iv = (np.nan_to_num(offs[..., k] - 0.5, nan=-1).astype(int) for k in (0, 1))
    assert np.array_equal(out[filled], colours[iv[filled], iu[filled]])  # a dependent lookup, as the GPU does
    assert np.isnan(offs[~filled]).all() and (out[~filled] == 0).all()
    assert 0.0 <= splat.hole_fraction < 0.5


def test_no_holes_left_for_a_smooth_height_field_under_moderate_view_changes():
    w = h = 64
    y, x = np.mgrid[0:h, 0:w] / w
    d = 0.15 * (1 + np.sin(4 * x) * np.cos(3 * y))
    frame = pw.ReliefFrame(np.array([-3.2, -3.2, 0.0]), np.array([0.1, 0, 0]), np.array([0, 0.1, 0]),
                           np.array([0, 0, 1.0]))
    fractions = []
    for angle in np.radians([0, 10, 20, 30]):
        eye = np.array([8 * np.sin(angle), 0.0, 8 * np.cos(angle)])
        raw = pw.forward_splat(d, frame, eye)
        fractions.append(raw.hole_fraction)
        filled = pw.fill_holes(raw)
        assert filled.hole_fraction == 0.0
        painted = raw.source >= 0
        assert np.array_equal(filled.source[painted], raw.source[painted])  # painted texels are kept
    assert fractions[-1] > fractions[0]  # the raw holes grow with the view change; filled, there are none


def _along_rows(painted):
    """Texels with something painted on both sides along their row (or painted): (H, W) bool."""
    return np.maximum.accumulate(painted, axis=1) & np.maximum.accumulate(painted[:, ::-1], axis=1)[:, ::-1]


def _enclosed(painted):
    """Texels enclosed along their row and along their column: (H, W) bool."""
    return _along_rows(painted) & _along_rows(painted.T).T


@pytest.mark.parametrize("eye", ([0.3, 0.2, 5.4], [0.6, 0.0, 5.0]))
def test_a_sphere_seen_off_its_boards_axis_keeps_no_hole_inside_its_outline(eye):
    """The live board of a sphere, its plane behind it (displacements 1.75 to 2.75) and the eye moved off the axis
    it was rendered along: the front's texels spread into gaps longer than the preview's gap both ways, which one row
    and column pass leaves (the viewport showed them as specks through the board); the passes repeat until none is
    left inside the outline, and nothing is painted outside the outline (of the depth-buffered splat, closed along
    rows and columns)."""
    n = 200
    y, x = (np.mgrid[0:n, 0:n] + 0.5) / n * 2.6 - 1.3
    present = x * x + y * y < 1.0
    d = np.where(present, 1.75 + np.sqrt(np.clip(1.0 - x * x - y * y, 0.0, None)), 0.0)
    size = 2.6 / n
    frame = pw.ReliefFrame(np.array([-1.3, -1.3, 0.0]), np.array([size, 0, 0]), np.array([0, size, 0]),
                           np.array([0, 0, 1.0]))
    raw = pw.forward_splat(d, frame, np.array(eye), present)
    once = pw.fill_holes(raw, 4, passes=1)
    filled = pw.fill_holes(raw, 4)
    assert (_enclosed(once.source >= 0) & (once.source < 0)).sum() > 10  # what one pass left
    assert (_enclosed(filled.source >= 0) & (filled.source < 0)).sum() == 0
    oracle = pw.zbuffer_splat(d, frame, np.array(eye), present).source >= 0
    columns_then_rows = _along_rows(_along_rows(oracle.T).T)
    outside = ~(columns_then_rows | _along_rows(_along_rows(oracle).T).T)  # the sphere's outline is convex
    assert outside.sum() > 2000 and (filled.source[outside] < 0).all()  # nothing painted outside the outline

"""NURBS splines as Blender holds them, split into rational Bézier pieces and patches (`kernels.common.curves.nurbs`),
checked against an independent evaluator (geomdl, NURBS-Python) on random splines of every order, knot mode, weights
and cyclic setting; Blender's own knots and evaluation are checked in `tests/surfaces/test_blender_nurbs.py`."""

import itertools

import numpy as np
import pytest
from geomdl import NURBS
from tessera.kernels.common.curves import nurbs as nb
from tessera.kernels.common.curves import rational_bezier as rb
from tessera.kernels.common.errors import InvalidInputError

MODES = ("UNIFORM", "ENDPOINT", "BEZIER", "ENDPOINT_BEZIER")


def valid_count(order, mode, cyclic, n):
    """A point count at least n that Blender draws as a curve for these settings."""
    n = max(n, order)
    while True:
        try:
            nb.direction_knots(n, nb.Direction(order, mode, cyclic))
            return n
        except InvalidInputError:
            n += 1


def geomdl_curve(points_h, knots, order):
    c = NURBS.Curve()
    c.degree = order - 1
    c.ctrlptsw = points_h.tolist()
    c.knotvector = knots.tolist()
    return c


def bezier_point(piece, s):
    return rb.cartesian(rb.curve_points(piece[None], np.array([s]))[0, 0])


def test_blender_knot_vectors():
    assert nb.blender_knots(6, 4, "ENDPOINT", False).tolist() == [0, 0, 0, 0, 1, 2, 3, 3, 3, 3]
    assert nb.blender_knots(5, 3, "UNIFORM", False).tolist() == list(range(8))
    assert nb.blender_knots(7, 3, "ENDPOINT_BEZIER", False).tolist() == [0, 0, 0, 1, 1, 2, 2, 3, 3, 3]
    # a cyclic tail longer than the rest repeats the knots it has just written: still uniform
    assert nb.blender_knots(6, 6, "UNIFORM", True).tolist() == list(range(17))
    assert nb.blender_knots(8, 3, "ENDPOINT_BEZIER", True).tolist() == [0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 6, 6]


@pytest.mark.parametrize("order", range(2, 7))
def test_curve_pieces_match_an_independent_evaluator(order):
    rng = np.random.default_rng(order)
    for mode, cyclic in itertools.product(MODES, (False, True)):
        n = valid_count(order, mode, cyclic, int(rng.integers(order, 11)))
        co = np.c_[rng.normal(size=(n, 3)), rng.uniform(0.2, 4.0, n)]
        d = nb.Direction(order, mode, cyclic)
        pieces, span = nb.curve_pieces(co, d)
        knots = nb.direction_knots(n, d)
        ref = geomdl_curve(nb.homogeneous(nb.wrap_cyclic(co, order, cyclic)), knots, order)
        lo, hi = knots[0], knots[-1]
        for s, (a, b) in enumerate(span):
            for f in (0.02, 0.3, 0.71, 0.98):  # inside the span: geomdl cannot take a knot of a zero span
                x = a + f * (b - a)
                want = np.array(ref.evaluate_single(float((x - lo) / (hi - lo))))
                assert np.abs(bezier_point(pieces[s], f) - want).max() < 1e-9 * (1 + np.abs(want).max()), \
                    (order, mode, cyclic, s, f)
        # pieces meet exactly; a cyclic curve closes exactly
        assert np.array_equal(pieces[1:, 0], pieces[:-1, -1])
        if cyclic:
            assert np.array_equal(pieces[-1, -1], pieces[0, 0])


def test_surface_patches_match_an_independent_evaluator():
    rng = np.random.default_rng(7)
    cases = [(3, 3, "ENDPOINT_BEZIER", "ENDPOINT_BEZIER", False, True), (4, 2, "UNIFORM", "ENDPOINT", True, False),
             (5, 6, "ENDPOINT", "UNIFORM", False, False), (2, 4, "BEZIER", "UNIFORM", True, True),
             (6, 3, "UNIFORM", "BEZIER", True, False)]
    for ku, kv, mu, mv, cu, cv in cases:
        nu = valid_count(ku, mu, cu, int(rng.integers(ku, 9)))
        nv = valid_count(kv, mv, cv, int(rng.integers(kv, 9)))
        co = np.concatenate([rng.normal(size=(nv, nu, 3)), rng.uniform(0.3, 3.0, (nv, nu, 1))], axis=2)
        u, v = nb.Direction(ku, mu, cu), nb.Direction(kv, mv, cv)
        patches, (su, sv), span_u, span_v = nb.surface_patches(co, u, v)
        assert patches.shape == (su * sv, ku, kv, 4)
        wrapped = nb.wrap_cyclic(nb.wrap_cyclic(co, ku, cu, axis=1), kv, cv, axis=0)
        kn_u, kn_v = nb.direction_knots(nu, u), nb.direction_knots(nv, v)
        ref = NURBS.Surface()
        ref.degree_u, ref.degree_v = ku - 1, kv - 1
        ref.ctrlpts_size_u, ref.ctrlpts_size_v = wrapped.shape[1], wrapped.shape[0]
        ref.ctrlptsw = nb.homogeneous(wrapped).transpose(1, 0, 2).reshape(-1, 4).tolist()  # u-major, v fastest
        ref.knotvector_u, ref.knotvector_v = kn_u.tolist(), kn_v.tolist()
        for q in range(len(patches)):
            i, j = divmod(q, sv)
            for fu, fv in ((0.01, 0.02), (0.25, 0.8), (0.99, 0.5), (0.6, 0.97)):
                x = span_u[i, 0] + fu * (span_u[i, 1] - span_u[i, 0])
                y = span_v[j, 0] + fv * (span_v[j, 1] - span_v[j, 0])
                want = np.array(ref.evaluate_single(((x - kn_u[0]) / (kn_u[-1] - kn_u[0]),
                                                     (y - kn_v[0]) / (kn_v[-1] - kn_v[0]))))
                bu, bv = rb.bernstein(fu, ku - 1), rb.bernstein(fv, kv - 1)
                got = rb.cartesian(np.einsum("i,j,ijc->c", bu, bv, patches[q]))
                assert np.abs(got - want).max() < 1e-9 * (1 + np.abs(want).max()), (ku, kv, q, fu, fv)
        # neighbouring patches share their sides bitwise; cyclic directions close bitwise
        grid = patches.reshape(su, sv, ku, kv, 4)
        assert np.array_equal(grid[1:, :, 0], grid[:-1, :, -1]) and np.array_equal(grid[:, 1:, :, 0],
                                                                                   grid[:, :-1, :, -1])
        if cu:
            assert np.array_equal(grid[0, :, 0], grid[-1, :, -1])
        if cv:
            assert np.array_equal(grid[:, 0, :, 0], grid[:, -1, :, -1])


def test_splines_of_mixed_orders_become_patches_of_one_degree_on_the_same_surface():
    rng = np.random.default_rng(3)
    a = nb.SurfaceSpline(np.concatenate([rng.normal(size=(3, 5, 3)), rng.uniform(.5, 2, (3, 5, 1))], 2),
                         nb.Direction(3, "ENDPOINT"), nb.Direction(2, "UNIFORM"))
    b = nb.SurfaceSpline(np.concatenate([rng.normal(size=(5, 5, 3)), np.ones((5, 5, 1))], 2),
                         nb.Direction(5, "ENDPOINT"), nb.Direction(4, "UNIFORM", True))
    ps = nb.patches_of([a, b])
    patches, owner = ps.patches, ps.spline
    assert patches.shape[1:] == (5, 5, 4) and set(owner) == {0, 1}
    # each patch's box in its spline's [0, 1]: a's 3 spans along u, 2 along v (uniform knots, order 2: 2 spans)
    assert np.allclose(ps.box[owner == 0, 0], [[0, 1 / 3], [0, 1 / 3], [1 / 3, 2 / 3], [1 / 3, 2 / 3], [2 / 3, 1],
                                              [2 / 3, 1]])
    assert np.allclose(ps.box[owner == 0, 1], [[0, .5], [.5, 1]] * 3)
    assert np.allclose(ps.uv(np.array([0, 5]), np.array([[.5, .5], [1, 1]])), [[1 / 6, .25], [1, 1]])
    # and back: any (u, v) of spline 1 to its patch and the place in it, borders and ends included
    uv = np.concatenate([rng.random((50, 2)), [[0, 0], [1, 1], [0.5, 1], [1, 0.25]]])
    patch, st = ps.locate(uv, spline=1)
    assert (owner[patch] == 1).all() and (st >= -1e-12).all() and (st <= 1 + 1e-12).all()
    assert np.allclose(ps.uv(patch, st), uv)
    first = nb.surface_patches(a.points, a.u, a.v)[0]
    for f in (0.0, 0.37, 1.0):
        for g in (0.0, 0.5, 0.9):
            want = rb.cartesian(np.einsum("i,j,pijc->pc", rb.bernstein(f, 2), rb.bernstein(g, 1), first))
            got = rb.cartesian(np.einsum("i,j,pijc->pc", rb.bernstein(f, 4), rb.bernstein(g, 4),
                                         patches[owner == 0]))
            assert np.abs(got - want).max() < 1e-12


@pytest.mark.parametrize("points, direction, words", [
    (np.array([[0, 0, 0, 1], [1, 0, 0, 0], [2, 1, 0, 1]]), nb.Direction(3), "weights of zero or less"),
    (np.array([[0, 0, 0, 1], [1, 0, 0, -2], [2, 1, 0, 1]]), nb.Direction(3), "weights of zero or less"),
    (np.array([[0, 0, 0, 1], [np.nan, 0, 0, 1], [2, 1, 0, 1]]), nb.Direction(3), "NaN or infinite"),
    (np.array([[0, 0, 0, 1]]), nb.Direction(2), "at least 2"),
    (np.array([[0, 0, 0, 1], [1, 0, 0, 1], [2, 1, 0, 1]]), nb.Direction(4), "lower its Order to 3"),
    (np.array([[0, 0, 0, 1], [1, 0, 0, 1], [2, 1, 0, 1]]), nb.Direction(7), "orders 2 to 6"),
    (np.ones((7, 4)), nb.Direction(4, "BEZIER", True), "need 2 more point"),
])
def test_bad_splines_are_refused_with_the_reason(points, direction, words):
    with pytest.raises(InvalidInputError, match=words):
        nb.curve_pieces(points, direction)


def test_splines_of_one_shape_converted_together_equal_each_alone_and_a_bad_one_is_named():
    rng = np.random.default_rng(9)
    u, v = nb.Direction(4, "UNIFORM", True), nb.Direction(3, "ENDPOINT")
    same = [nb.SurfaceSpline(np.concatenate([rng.normal(size=(4, 6, 3)), rng.uniform(.5, 2, (4, 6, 1))], 2), u, v)
            for _ in range(3)]
    other = nb.SurfaceSpline(np.concatenate([rng.normal(size=(3, 5, 3)), np.ones((3, 5, 1))], 2),
                             nb.Direction(3, "ENDPOINT"), nb.Direction(2, "UNIFORM"))
    splines = [same[0], other, same[1], same[2]]  # a group interleaved with another shape
    together = nb.patches_of(splines)
    for i, sp in enumerate(splines):
        alone = nb.patches_of([sp, other] if i != 1 else [other, same[0]])  # the same degree as together
        mine = together.patches[together.spline == i]
        assert np.array_equal(mine, alone.patches[alone.spline == 0])  # bit for bit
        assert np.array_equal(together.box[together.spline == i], alone.box[alone.spline == 0])
    bad = nb.SurfaceSpline(same[2].points.copy(), u, v)
    bad.points[1, 2, 3] = 0.0
    with pytest.raises(InvalidInputError, match="surface spline 3 has weights of zero"):
        nb.patches_of([same[0], other, same[1], bad])

def test_tolerance_steps_meet_the_tolerance_measured_densely():
    rng = np.random.default_rng(11)
    pieces, _ = nb.curve_pieces(np.c_[rng.normal(size=(9, 3)) * 3, rng.uniform(0.2, 5.0, 9)],
                                nb.Direction(5, "ENDPOINT"))
    for tol in (1e-1, 1e-2, 1e-4):
        steps, dev = rb.tolerance_steps(pieces, tol, 100000)
        assert (dev <= tol).all()
        for piece, n in zip(pieces, steps, strict=True):  # 64 points in every step
            t = np.arange(n * 64 + 1) / (n * 64)
            dense = rb.cartesian(rb.curve_points(piece[None], t)[0])
            ends = dense[::64]
            chord = np.repeat(ends[:-1], 64, axis=0) + (np.tile(np.arange(64), n) / 64)[:, None] * (
                np.repeat(ends[1:] - ends[:-1], 64, axis=0))
            assert np.linalg.norm(dense[:-1] - chord, axis=1).max() <= tol
        if tol == 1e-4:  # and not far over what is needed: one step fewer would be over
            fewer = rb.chord_deviation(pieces, np.maximum(steps - 1, 1))
            assert (fewer[steps > 1] > 0.5 * tol).all()


def test_custom_knots_are_taken_as_given_and_checked():
    rng = np.random.default_rng(2)
    co = np.c_[rng.normal(size=(7, 3)), rng.uniform(0.5, 2.0, 7)]
    blender = nb.Direction(4, "ENDPOINT")
    knots = nb.blender_knots(7, 4, "ENDPOINT", False)
    same, _ = nb.curve_pieces(co, nb.Direction(4, "CUSTOM", knots=tuple(knots)))
    assert np.array_equal(same, nb.curve_pieces(co, blender)[0])
    uneven = knots.copy()
    uneven[4:7] = [0.5, 2.5, 2.75]  # inner knots moved: other pieces, the same curve ends
    pieces, span = nb.curve_pieces(co, nb.Direction(4, "CUSTOM", knots=tuple(uneven)))
    assert np.allclose(span[:, 0], [0, 0.5, 2.5, 2.75]) and np.array_equal(pieces[0, 0], same[0, 0])
    with pytest.raises(InvalidInputError, match="non-decreasing"):
        nb.curve_pieces(co, nb.Direction(4, "CUSTOM", knots=tuple(knots[::-1])))
    with pytest.raises(InvalidInputError, match="must be 11"):
        nb.curve_pieces(co, nb.Direction(4, "CUSTOM", knots=tuple(knots[:-1])))

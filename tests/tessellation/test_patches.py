"""PN triangles and Phong tessellation: the properties [Vlachos 2001] and [Boubekeur 2008] state ([Nunes 2011, ch.
3])."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from tessera.kernels.common.tolerances import PATCH_IDENTITY_ATOL
from tessera.kernels.tessellation import patches

CORNERS = np.eye(3)


def random_triangle(seed, flat=False):
    rng = np.random.default_rng(seed)
    p = rng.normal(size=(3, 3))
    if flat:
        face = np.cross(p[1] - p[0], p[2] - p[0])
        n = np.tile(face / np.linalg.norm(face), (3, 1))
    else:
        n = rng.normal(size=(3, 3))
        n /= np.linalg.norm(n, axis=1, keepdims=True)
    return p, n


def random_bary(seed, count=50):
    b = np.random.default_rng(seed).dirichlet((1, 1, 1), size=count)
    return np.concatenate([b, CORNERS, [[0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]]])


def pn_eval(p, n, bary):
    return patches.cubic_basis(bary) @ patches.pn_control(p[None], n[None])[0]


def pn_normal_eval(p, n, bary):
    raw = patches.quadratic_basis(bary) @ patches.pn_normal_control(p[None], n[None])[0]
    return raw / np.linalg.norm(raw, axis=1, keepdims=True)


def phong_eval(p, n, bary, alpha):
    return patches.quadratic_basis(bary) @ patches.phong_control(p[None], n[None], alpha)[0]


seeds = st.integers(0, 2**32 - 1)


# -- PN triangles ---------------------------------------------------------------------------------------

@given(seeds)
def test_pn_interpolates_corners_positions_and_normals(seed):
    p, n = random_triangle(seed)
    assert np.array_equal(pn_eval(p, n, CORNERS), p)
    np.testing.assert_allclose(pn_normal_eval(p, n, CORNERS), n, atol=1e-15)


@given(seeds)
def test_pn_linear_precision(seed):
    p, n = random_triangle(seed, flat=True)
    bary = random_bary(seed)
    control = patches.pn_control(p[None], n[None])[0]
    np.testing.assert_allclose(control[9], p.mean(axis=0), atol=PATCH_IDENTITY_ATOL)  # b111 = V
    np.testing.assert_allclose(pn_eval(p, n, bary), bary @ p, atol=PATCH_IDENTITY_ATOL)
    np.testing.assert_allclose(pn_normal_eval(p, n, bary), np.broadcast_to(n[0], (len(bary), 3)), atol=1e-12)


@given(seeds)
def test_pn_edge_control_points_lie_in_the_corner_tangent_planes(seed):
    p, n = random_triangle(seed)
    c = patches.pn_control(p[None], n[None])[0]
    # b210, b201 near P1; b120, b021 near P2; b012, b102 near P3.
    for index, corner in ((3, 0), (8, 0), (4, 1), (5, 1), (6, 2), (7, 2)):
        assert abs((c[index] - p[corner]) @ n[corner]) < 1e-12


@given(seeds)
def test_pn_centre_control_point_rule(seed):
    p, n = random_triangle(seed)
    c = patches.pn_control(p[None], n[None])[0]
    e = c[3:9].mean(axis=0)
    v = p.mean(axis=0)
    np.testing.assert_allclose(c[9], e + (e - v) / 2, atol=PATCH_IDENTITY_ATOL)


@given(seeds)
def test_pn_mid_edge_normals_are_reflections(seed):
    p, n = random_triangle(seed)
    nc = patches.pn_normal_control(p[None], n[None])[0]
    for column, (i, j) in zip((3, 4, 5), patches.QUADRATIC_PAIRS, strict=True):
        d = p[j] - p[i]
        plane = d / np.linalg.norm(d)
        s = n[i] + n[j]
        reflected = s - 2 * (s @ plane) * plane  # Householder reflection across the plane with normal d
        np.testing.assert_allclose(nc[column], reflected / np.linalg.norm(reflected), atol=1e-12)


def test_pn_normal_patch_has_unit_mixed_coefficients():
    # At the edge midpoint of 0-1 the quadratic normal is normalize(N1/4 + N2/4 + n110/4): coefficient 1.
    p, n = random_triangle(7)
    nc = patches.pn_normal_control(p[None], n[None])[0]
    expected = (n[0] + n[1] + nc[3]) / 4
    got = patches.quadratic_basis(np.array([[0.5, 0.5, 0.0]])) @ nc
    np.testing.assert_allclose(got[0], expected, atol=1e-15)


@given(seeds)
def test_pn_boundary_curve_depends_only_on_its_edge(seed):
    rng = np.random.default_rng(seed)
    p, n = random_triangle(seed)
    q, m = p.copy(), n.copy()
    q[2] += rng.normal(size=3)  # move the third corner and its normal
    m[2] = rng.normal(size=3)
    m[2] /= np.linalg.norm(m[2])
    t = np.linspace(0, 1, 17)
    bary = np.stack([1 - t, t, np.zeros_like(t)], 1)
    np.testing.assert_allclose(pn_eval(p, n, bary), pn_eval(q, m, bary), atol=1e-13)
    np.testing.assert_allclose(pn_normal_eval(p, n, bary), pn_normal_eval(q, m, bary), atol=1e-13)
    edge = patches.cubic_edge_basis(t) @ patches.pn_edge_control(p[0], p[1], n[0], n[1])
    np.testing.assert_allclose(edge, pn_eval(p, n, bary), atol=1e-13)
    edge_n = patches.quadratic_edge_basis(t) @ patches.pn_edge_normal_control(p[0], p[1], n[0], n[1])
    np.testing.assert_allclose(edge_n / np.linalg.norm(edge_n, axis=1, keepdims=True), pn_normal_eval(p, n, bary),
                               atol=1e-12)


def test_quadratic_normals_show_an_inflection_that_linear_normals_miss():
    # An S-shaped profile: the normals at both ends of an edge are equal but the edge is not
    # perpendicular to them, so the surface bends both ways (the "sleeve fold" of Figs 3.19/3.20).
    p = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.4], [0.5, 1.0, 0.2]])
    n = np.tile([0.0, 0.0, 1.0], (3, 1))
    mid = np.array([[0.5, 0.5, 0.0]])
    quadratic = pn_normal_eval(p, n, mid)[0]
    linear = patches.linear_basis(mid) @ n
    assert np.allclose(linear[0], [0, 0, 1])
    assert quadratic @ np.array([0.0, 0.0, 1.0]) < 0.99  # tilted at the fold
    assert quadratic[0] < -0.1  # toward -x: the side the 0.4 rise faces


def test_degenerate_inputs_stay_finite():
    p = np.zeros((3, 3))  # all corners together
    n = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.0, 0.0, 1.0]])  # opposite normals
    for control in (patches.pn_control(p[None], n[None]), patches.pn_normal_control(p[None], n[None]),
                    patches.phong_control(p[None], n[None])):
        assert np.all(np.isfinite(control))


# -- Phong tessellation ---------------------------------------------------------------------------------

@given(seeds)
def test_projection_lies_on_the_plane_and_is_idempotent(seed):
    rng = np.random.default_rng(seed)
    q, point, normal = rng.normal(size=(3, 3))
    normal /= np.linalg.norm(normal)
    once = patches.project_to_plane(q, point, normal)
    assert abs((once - point) @ normal) < 1e-12
    np.testing.assert_allclose(patches.project_to_plane(once, point, normal), once, atol=1e-12)


@settings(max_examples=50)
@given(seeds, st.floats(0, 1.5))
def test_phong_quadratic_form_equals_the_seed_projections(seed, alpha):
    p, n = random_triangle(seed)
    bary = random_bary(seed)
    np.testing.assert_allclose(phong_eval(p, n, bary, alpha), patches.phong_direct(p, n, bary, alpha), atol=1e-12)


@given(seeds)
def test_phong_interpolates_corners_and_reproduces_flat_triangles(seed):
    p, n = random_triangle(seed)
    assert np.array_equal(phong_eval(p, n, CORNERS, 0.75), p)
    pf, nf = random_triangle(seed, flat=True)
    bary = random_bary(seed)
    np.testing.assert_allclose(phong_eval(pf, nf, bary, 1.0), bary @ pf, atol=PATCH_IDENTITY_ATOL)


@given(seeds)
def test_phong_alpha_limits(seed):
    p, n = random_triangle(seed)
    bary = random_bary(seed)
    assert np.array_equal(phong_eval(p, n, bary, 0.0), patches.quadratic_basis(bary) @ np.concatenate(
        [p, [p[0] + p[1], p[1] + p[2], p[2] + p[0]]]))
    np.testing.assert_allclose(phong_eval(p, n, bary, 0.0), bary @ p, atol=PATCH_IDENTITY_ATOL)
    np.testing.assert_allclose(phong_eval(p, n, bary, 1.0), patches.phong_direct(p, n, bary, 1.0), atol=1e-12)


@given(seeds)
def test_phong_is_quadratic_third_differences_vanish(seed):
    p, n = random_triangle(seed)
    h = 0.05
    for direction in (np.array([-1.0, 1.0, 0.0]), np.array([-1.0, 0.0, 1.0]), np.array([0.0, -1.0, 1.0])):
        start = np.array([0.8, 0.1, 0.1]) - 1.5 * h * direction
        samples = np.array([start + k * h * direction for k in range(4)])
        values = patches.phong_direct(p, n, samples, 1.0)
        third = values[3] - 3 * values[2] + 3 * values[1] - values[0]
        assert np.abs(third).max() < 1e-12
        second = values[2] - 2 * values[1] + values[0]
        assert np.abs(second).max() > 1e-6 or np.allclose(n, n[0])  # genuinely quadratic


@given(seeds)
def test_phong_edge_depends_only_on_its_edge(seed):
    p, n = random_triangle(seed)
    q, m = p.copy(), n.copy()
    q[2] += 1.0
    m[2] = np.array([1.0, 0.0, 0.0])
    t = np.linspace(0, 1, 9)
    bary = np.stack([1 - t, t, np.zeros_like(t)], 1)
    np.testing.assert_allclose(phong_eval(p, n, bary, 0.75), phong_eval(q, m, bary, 0.75), atol=1e-13)
    edge = patches.quadratic_edge_basis(t) @ patches.phong_edge_control(p[0], p[1], n[0], n[1], 0.75, 0.75)
    np.testing.assert_allclose(edge, phong_eval(p, n, bary, 0.75), atol=1e-13)


def test_per_vertex_alpha_matches_the_papers_blend():
    p, n = random_triangle(3)
    bary = random_bary(3)
    alphas = np.array([0.0, 0.5, 1.0])
    offset = patches.quadratic_basis(bary) @ patches.phong_offset_control(p[None], n[None])[0]
    got = bary @ p + (bary @ alphas)[:, None] * offset
    linear = bary @ p
    full = patches.phong_direct(p, n, bary, 1.0)
    expected = linear + (bary @ alphas)[:, None] * (full - linear)
    np.testing.assert_allclose(got, expected, atol=1e-12)


@pytest.mark.parametrize("alpha", [0.0, 0.75, 1.0])
def test_phong_edge_offset_form_agrees_with_constant_alpha(alpha):
    p, n = random_triangle(11)
    t = np.linspace(0, 1, 9)
    direct = patches.quadratic_edge_basis(t) @ patches.phong_edge_control(p[0], p[1], n[0], n[1], alpha, alpha)
    linear = patches.linear_edge_basis(t) @ p[:2]
    offset = patches.quadratic_edge_basis(t) @ patches.phong_edge_offset_control(p[0], p[1], n[0], n[1])
    np.testing.assert_allclose(direct, linear + alpha * offset, atol=1e-12)


def test_bases_have_the_bits_of_their_written_expressions():
    """The bases fill their columns with products only (no pow, whose SIMD paths round differently per CPU) and share
    leading products (((3 b0) b0) b1 and ((3 b0) b0) b2 share 3 b0 b0); each column still has the bits of its
    expression evaluated alone, left to right, so every stored output keeps its bytes on every machine."""
    rng = np.random.default_rng(4)
    b = np.concatenate([rng.dirichlet((1, 1, 1), 5000), np.eye(3), [[1 / 3] * 3], -rng.random((50, 3)) * 1e-200,
                        rng.normal(size=(50, 3)) * 1e155])
    with np.errstate(over="ignore", under="ignore"):  # the huge and tiny rows overflow and underflow alike
        b0, b1, b2 = b[:, 0], b[:, 1], b[:, 2]
        cubic = np.stack([b0 * b0 * b0, b1 * b1 * b1, b2 * b2 * b2, 3 * b0 * b0 * b1, 3 * b0 * b1 * b1,
                          3 * b1 * b1 * b2, 3 * b1 * b2 * b2, 3 * b0 * b2 * b2, 3 * b0 * b0 * b2,
                          6 * b0 * b1 * b2], axis=1)
        quadratic = np.stack([b0 * b0, b1 * b1, b2 * b2, b0 * b1, b1 * b2, b2 * b0], axis=1)
        for got, want in ((patches.cubic_basis(b), cubic), (patches.quadratic_basis(b), quadratic)):
            assert got.shape == want.shape and np.ascontiguousarray(got).tobytes() == want.tobytes()

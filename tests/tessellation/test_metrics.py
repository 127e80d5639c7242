"""Adaptive metrics: worked values of [Nellmedin 2014, ch. 4]."""

import numpy as np
import pytest
from tessera.kernels.common.camera import perspective
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.tessellation import metrics

DISTANCES = [1, 2, 5, 10, 25, 51, 75, 101]
LINEAR = [64, 63.37, 61.48, 58.33, 48.88, 32.5, 17.38, 1]
INVERSE = [64, 32.185, 13.096, 6.733, 2.915, 1.618, 1.218, 1]


def test_distance_table():
    np.testing.assert_allclose(metrics.distance_level(DISTANCES, 1, 101, 64, "LINEAR"), LINEAR, atol=5e-3)
    np.testing.assert_allclose(metrics.distance_level(DISTANCES, 1, 101, 64, "INVERSE"), INVERSE, atol=5e-4)
    assert metrics.distance_level(51, 1, 101, 64, "INVERSE") == pytest.approx(1.6176, abs=1e-4)


def test_distance_is_clamped_outside_its_range():
    assert metrics.distance_level(0.5, 1, 101, 64, "LINEAR") == 64
    assert metrics.distance_level(500, 1, 101, 64, "LINEAR") == 1
    assert metrics.distance_level(0.5, 1, 101, 64, "INVERSE") == 64
    assert metrics.distance_level(500, 1, 101, 64, "INVERSE") == 1
    with pytest.raises(InvalidInputError):
        metrics.distance_level(5, 10, 1, 64)


CURVES = [
    ([(0, 0), (1, 0), (2, 0), (3, 0)], 0.0, 6),
    ([(0, 0), (0, 1), (1, 1), (1, 0)], 0.5, 6),
    ([(0, 0), (1, 4), (2, 0), (3, 0)], 2.0, 20),
    ([(0, 0), (7, 28), (14, 0), (21, 0)], 2.0, 20),
    ([(0, 0), (1, 10), (2, 0), (3, 0)], 5.0, 32),
    ([(0, 0), (5, 6), (10, 0)], 0.6, 6),
    ([(0, 0), (5, 10), (10, 0)], 1.0, 10),
]


@pytest.mark.parametrize(("points", "kappa", "level"), CURVES)
def test_curvature_table(points, kappa, level):
    c = np.array(points, np.float64)
    k = metrics.curve_kappa(c)
    assert k == pytest.approx(kappa, abs=1e-12)
    assert metrics.curvature_level(k, n_control=len(c)) == pytest.approx(level)


def test_degenerate_chord_counts_as_the_cap():
    assert metrics.curve_kappa(np.array([[0, 0], [1, 1], [0, 0]], float)) == np.inf
    assert metrics.curvature_level(np.inf) == 32
    assert metrics.curve_kappa(np.zeros((4, 2))) == 0


def test_projected_edge_example_640x480():
    # An edge whose sphere covers NDC length 0.5 in y on a 480-pixel-high view: 120 px, e_max 10 -> level 12.
    fov = np.radians(60.0)
    proj = perspective(fov, 640 / 480, 0.1, 100.0)
    z = 4.0
    d = 0.5 * np.tan(fov / 2) * z  # NDC length l = cot(fov/2) * d / z = 0.5
    a, b = np.array([-d / 2, 0.0, -z]), np.array([d / 2, 0.0, -z])
    level = metrics.projected_edge_levels(a, b, np.eye(4), proj, 480, 10.0)
    assert level == pytest.approx(12.0, rel=1e-12)


def test_projected_edge_does_not_depend_on_orientation():
    rng = np.random.default_rng(3)
    proj = perspective(np.radians(50), 1.5, 0.1, 100)
    mid = np.array([0.3, -0.2, -6.0])
    dirs = rng.normal(size=(20, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    levels = metrics.projected_edge_levels(mid - dirs * 0.7, mid + dirs * 0.7, np.eye(4), proj, 720, 4.0)
    np.testing.assert_allclose(levels, levels[0], rtol=1e-12)
    swapped = metrics.projected_edge_levels(mid + dirs * 0.7, mid - dirs * 0.7, np.eye(4), proj, 720, 4.0)
    assert np.array_equal(levels, swapped)


def test_projected_edge_behind_the_camera():
    proj = perspective(np.radians(50), 1, 0.1, 100)
    behind = metrics.projected_edge_levels([0, 0, 5.0], [0, 1, 5.0], np.eye(4), proj, 500, 10, 64)
    crossing = metrics.projected_edge_levels([0, 0, 1.0], [0, 0, -1.0], np.eye(4), proj, 500, 10, 64)
    assert behind == 1 and crossing == 64


def silhouette_case(other_normal):
    a, b = np.array([0.0, -1.0, 0.0]), np.array([0.0, 1.0, 0.0])
    eye = np.array([5.0, 0.0, 0.0])
    return metrics.silhouette_products(a, b, np.array([1.0, 0.0, 0.0]), np.asarray(other_normal, float), eye)


def test_silhouette_cases():
    u, u_hat = silhouette_case([-1.0, 0.0, 0.0])  # front face next to a back face: silhouette
    assert u < 0 and metrics.silhouette_edge_levels(u, 64) == 64
    u, _ = silhouette_case([0.6, 0.8, 0.0])  # both front facing
    assert u > 0 and metrics.silhouette_edge_levels(u, 64) == 1
    # The product is symmetric: the neighbour computes the same value bit for bit.
    a, b = np.array([0.1, -1.0, 0.3]), np.array([0.2, 1.0, -0.1])
    n1, n2 = np.array([0.8, 0.6, 0.0]), np.array([-0.6, 0.0, 0.8])
    eye = np.array([3.0, 0.5, 1.0])
    assert metrics.silhouette_products(a, b, n1, n2, eye) == metrics.silhouette_products(b, a, n2, n1, eye)


def test_silhouette_inner_ramp():
    t_max, beta = 64.0, 0.25
    u = np.array([[-1e-9, 1.0, 1.0]])
    assert metrics.silhouette_inner_levels(u, np.array([[0.0, 0.5, 0.5]]), t_max, beta)[0] == 64
    assert metrics.silhouette_inner_levels(u, np.array([[beta, 0.5, 0.5]]), t_max, beta)[0] == 1
    assert metrics.silhouette_inner_levels(u, np.array([[0.125, 0.5, 0.5]]), t_max, beta)[0] == 32.5
    assert metrics.silhouette_inner_levels(u, np.array([[0.3, 0.5, 0.5]]), t_max, beta)[0] == 1
    assert metrics.silhouette_inner_levels(np.array([[0.2, 1, 1]]), np.zeros((1, 3)), t_max, beta)[0] == 1


def test_power_of_two_rounding():
    got = metrics.clamp_and_round([18, 20, 3, 1, 64, 100], 64, "CEIL")
    assert got.tolist() == [32, 32, 4, 1, 64, 64]
    assert metrics.clamp_and_round([18, 20, 3], 64, "FLOOR").tolist() == [16, 16, 2]
    assert metrics.clamp_and_round([23, 22, 3], 64, "NEAREST").tolist() == [32, 16, 4]
    assert metrics.clamp_and_round([40], 48, "CEIL").tolist() == [32]  # never above the cap
    assert metrics.clamp_and_round([0.2, 70], 64).tolist() == [1, 64]
    with pytest.raises(InvalidInputError):
        metrics.clamp_and_round([1], 65)


def test_pn_inner_kappa_is_zero_on_a_flat_net_and_positive_on_a_bulge():
    from tessera.kernels.tessellation.patches import pn_control
    p = np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]])
    flat = np.tile([0.0, 0, 1], (1, 3, 1))
    assert metrics.pn_inner_kappa(pn_control(p, flat))[0] == pytest.approx(0, abs=1e-15)
    bulge = np.array([[[-1.0, -1, 1], [1, 0, 1], [0, 1, 1]]])
    bulge /= np.linalg.norm(bulge, axis=2, keepdims=True)
    assert metrics.pn_inner_kappa(pn_control(p, bulge))[0] > 0.01

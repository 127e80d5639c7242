"""Vector-field textures ([Nellmedin 2014, §5.5.4]): the fields, Euler advection, splatting, the camera's density."""

import numpy as np
import pytest
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.vector_field import fields, streaks


def test_euler_advection_is_eq_5_1():
    field = fields.AnalyticField("VORTEX")
    points, _ = streaks.seed_points(8)
    path = streaks.advect(points, field, 0.01, 5)
    for k in range(5):
        step = path[k] + np.float32(0.01) * field.at(path[k]).astype(np.float32)
        assert np.array_equal(path[k + 1], step.astype(np.float32))


def test_the_vortex_turns_round_the_centre_and_abc_is_its_formula():
    field = fields.AnalyticField("VORTEX")
    p = np.array([[0.8, 0.5], [0.5, 0.8]])
    v = field.at(p)
    assert np.allclose(np.einsum("ij,ij->i", v, p - 0.5), 0)  # tangential
    assert v[0, 1] > 0 and v[1, 0] < 0  # counter-clockwise
    abc = fields.AnalyticField("ABC", slice_z=0.3)
    q = np.random.default_rng(0).random((50, 2))
    a, b = np.sqrt(3), np.sqrt(2)
    want = np.stack([a * np.sin(0.3) + np.cos(2 * np.pi * q[:, 1]), b * np.sin(2 * np.pi * q[:, 0]) + a * np.cos(0.3)],
                    1) / (2 * np.pi)
    assert np.allclose(abc.at(q), want)
    with pytest.raises(InvalidInputError):
        fields.AnalyticField("GALE")


def test_a_grid_field_interpolates_its_vectors():
    rng = np.random.default_rng(1)
    values = rng.normal(size=(5, 7, 2))
    grid = fields.GridField(values)
    i, j = np.meshgrid(np.arange(7), np.arange(5))
    nodes = np.stack([i.ravel() / 6, j.ravel() / 4], 1)
    assert np.allclose(grid.at(nodes), values.reshape(-1, 2))
    # a linear field is reproduced exactly between the nodes
    lin = fields.GridField(np.stack([2 * i / 6 + 0.5 * j / 4, -j / 4], -1).astype(float))
    q = rng.random((40, 2))
    assert np.allclose(lin.at(q), np.stack([2 * q[:, 0] + 0.5 * q[:, 1], -q[:, 1]], 1))
    with pytest.raises(InvalidInputError):
        fields.GridField(np.full((3, 3, 2), np.nan))


def test_splat_means_and_streaks_follow_the_flow():
    path = np.array([[[0.05, 0.05], [0.95, 0.95], [1.5, 0.5]]])
    total, count = streaks.splat(path, np.array([1.0, 2.0, 3.0]), 10, 10)
    assert total[0, 0] == 1 and total[9, 9] == 2 and count.sum() == 2  # the outside point splats nothing
    # a uniform flow to +x: each row's pixels share values along x, not along y
    class East:
        @staticmethod
        def at(p):
            return np.tile([1.0, 0.0], (len(p), 1))

    img = streaks.streak_image(East(), 64, 64, 64, step=1 / 64, steps=40)
    along = np.abs(np.diff(img[:, 20:60], axis=1)).mean()
    across = np.abs(np.diff(img[:, 20:60], axis=0)).mean()
    assert along < 0.3 * across


def test_density_rises_as_the_camera_approaches():
    counts = [streaks.seeds_per_side(64, d, near=1.0, far=11.0) for d in (0.5, 1.0, 6.0, 11.0, 50.0)]
    assert counts == sorted(counts, reverse=True) and counts[0] == 256 and counts[-1] == 64
    with pytest.raises(InvalidInputError):
        streaks.seeds_per_side(64, 3.0, near=5.0, far=2.0)


def test_a_grid_mesh_becomes_a_field():
    rng = np.random.default_rng(5)
    i, j = np.meshgrid(np.arange(6), np.arange(4))
    pos = np.stack([2.0 * i.ravel() - 3, 1.0 * j.ravel() + 7, np.zeros(24)], 1)  # 10 x 3 units
    vec = np.stack([rng.normal(size=24), rng.normal(size=24), rng.normal(size=24)], 1)
    perm = rng.permutation(24)
    field = fields.grid_field_from_points(pos[perm], vec[perm])
    assert np.allclose(field.values.reshape(-1, 2), vec[:, :2] / [10.0, 3.0])
    with pytest.raises(InvalidInputError, match="not a regular grid"):
        fields.grid_field_from_points(pos[:-1], vec[:-1])
    with pytest.raises(InvalidInputError, match="flat"):
        fields.grid_field_from_points(pos * [1, 0, 1], vec)

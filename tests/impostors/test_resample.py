"""Resampling a rendered board to another resolution (`kernels.impostors.resample`): area means, the outline and
relief of a sphere kept, the board's place kept."""

import numpy as np
import pytest
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.impostors.board import board_setup
from tessera.kernels.impostors.resample import box_mean, resample_board


def test_box_mean_is_the_block_mean_and_keeps_sums():
    rng = np.random.default_rng(4)
    image = rng.random((60, 60, 2))
    blocks = image.reshape(20, 3, 20, 3, 2).mean(axis=(1, 3))
    assert np.allclose(box_mean(image, 20), blocks, rtol=0, atol=1e-12)
    for n_out in (7, 23, 41, 60, 90):  # any ratio, finer too: the mean over the square is kept
        out = box_mean(image, n_out)
        assert out.shape == (n_out, n_out, 2)
        assert np.allclose(out.mean(axis=(0, 1)), image.mean(axis=(0, 1)), rtol=0, atol=1e-12)
    assert np.allclose(box_mean(np.full((50, 50), 0.25), 17), 0.25, rtol=0, atol=1e-14)


def sphere_board(res_screen=500):
    """A unit sphere's board seen from -y, as the worker renders it: setup, colours, displacement, normals, present,
    and the analytic displacement and outline as functions of board-plane coordinates."""
    setup = board_setup(np.full(3, -1.0), np.full(3, 1.0), np.array([0.0, -9.0, 0.0]), res_screen, 0.5)
    n = setup.resolution

    def grid(k):
        c = (np.arange(k) + 0.5) / k * setup.size - setup.size / 2
        return np.meshgrid(c, c)

    def truth(k):
        x, y = grid(k)
        r2 = x * x + y * y
        return setup.size / 2 + np.sqrt(np.maximum(1 - r2, 0.0)), r2 < 1.0, np.sqrt(r2)

    d, present, _ = truth(n)
    x, y = grid(n)
    z = np.sqrt(np.maximum(1 - x * x - y * y, 0.0))
    normals = np.stack([x, y, z], -1) * present[..., None]
    colours = np.zeros((n, n, 4), np.float32)
    colours[present] = (0.8, 0.2, 0.1, 1.0)
    return setup, colours, np.where(present, d, 0.0), normals.astype(np.float32), present, truth


@pytest.mark.parametrize("divisor", [2, 2.7, 4])
def test_a_resampled_sphere_board_keeps_its_outline_relief_and_place(divisor):
    setup, colours, d, normals, present, truth = sphere_board()
    k = int(setup.resolution / divisor)
    new, c2, d2, n2, p2 = resample_board(setup, colours, d, normals, present, k)
    assert new.resolution == k and c2.shape == (k, k, 4) and d2.shape == (k, k) and p2.shape == (k, k)
    want_d, want_p, radius = truth(k)
    texel = setup.size / k
    boundary = np.abs(radius - 1.0) < 0.75 * texel  # texels the true outline passes through
    assert np.array_equal(p2[~boundary], want_p[~boundary])
    inner = radius < 1.0 - 2 * texel
    assert np.abs(d2[inner] - want_d[inner]).max() < 0.05 * texel + 1e-3  # area mean of a smooth cap
    assert np.allclose(c2[p2 & inner, :3], (0.8, 0.2, 0.1), atol=1e-5)
    assert np.allclose(np.linalg.norm(n2[p2], axis=-1), 1.0, atol=1e-5)
    assert np.allclose(new.frame.point(k, k, 0.0), setup.frame.point(setup.resolution, setup.resolution, 0.0))
    assert np.allclose(new.frame.origin, setup.frame.origin) and np.allclose(new.frame.f, setup.frame.f)
    assert new.size == setup.size and np.array_equal(new.camera_location, setup.camera_location)


def test_bad_boards_are_clear_errors():
    setup, colours, d, normals, present, _ = sphere_board()
    with pytest.raises(InvalidInputError):
        resample_board(setup, colours[1:], d, normals, present, 10)
    with pytest.raises(InvalidInputError):
        resample_board(setup, colours, d, normals, present, 0)

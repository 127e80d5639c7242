"""Tangent-space displacement reference (tier: kernel): the sampler, the frames, the UV orientation."""

import numpy as np
import pytest
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.displacement.tangent_space import (
    sample_linear,
    tangent_frames,
    tangent_offsets,
    triangle_tangents,
    uv_orientation,
)


def test_sampler_hits_texel_centres_interpolates_and_clamps():
    rng = np.random.default_rng(1)
    image = rng.normal(size=(5, 7, 3))
    i, j = np.mgrid[0:5, 0:7]
    centres = np.stack([(j + 0.5) / 7, (i + 0.5) / 5], axis=-1)
    assert np.allclose(sample_linear(image, centres), image)
    mid = sample_linear(image, np.array([[(1 + 1.0) / 7, (2 + 0.5) / 5]]))  # halfway between (2, 1) and (2, 2)
    assert np.allclose(mid, (image[2, 1] + image[2, 2]) / 2)
    assert np.allclose(sample_linear(image, np.array([[-3.0, 2.0]])), image[4, 0])  # clamped to the corner


def test_frames_are_orthonormal_and_follow_the_sign():
    rng = np.random.default_rng(2)
    n = rng.normal(size=(50, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    t0 = rng.normal(size=(50, 3))
    signs = rng.choice([-1.0, 1.0], 50)
    t, b = tangent_frames(n, t0, signs)
    frame = np.stack([t, b, n], axis=1)
    assert np.allclose(frame @ frame.transpose(0, 2, 1), np.eye(3), atol=1e-12)
    assert np.allclose(np.linalg.det(frame), signs)  # right-handed where the UVs are not mirrored
    assert np.all(np.sum(t * t0, axis=1) > 0)  # the tangent keeps its direction
    values = rng.uniform(size=(50, 3))
    off = tangent_offsets(values, n, t0, signs, mid_level=0.25, strength=2.0)
    assert np.allclose(np.einsum("kij,kj->ki", frame, off), (values - 0.25) * 2.0)
    with pytest.raises(InvalidInputError, match="parallel"):
        tangent_frames(n[:1], n[:1] * 3.0, signs[:1])


def test_orientation_and_triangle_tangents_of_a_mirrored_quad():
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [1, 0], [0, 0], [0, 1], [1, 1]], float)  # 2nd quad mirrored
    assert np.array_equal(uv_orientation(uv, np.array([0, 4])), [1.0, -1.0])
    corners = np.array([[[0, 0, 0], [2, 0, 0], [2, 3, 0]]] * 2, float)
    uvs = np.array([[[0, 0], [1, 0], [1, 1]], [[1, 0], [0, 0], [0, 1]]], float)
    tg = triangle_tangents(corners, uvs)
    assert np.allclose(tg[0, :, :3], [1, 0, 0]) and np.all(tg[0, :, 3] == 1)
    assert np.allclose(tg[1, :, :3], [-1, 0, 0]) and np.all(tg[1, :, 3] == -1)
    t, b = tangent_frames(np.array([[0.0, 0.0, 1.0]] * 2), tg[:, 0, :3], tg[:, 0, 3])
    assert np.allclose(b, [[0, 1, 0], [0, 1, 0]])  # V still runs along +Y: only U is mirrored

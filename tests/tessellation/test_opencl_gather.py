"""OpenCL gather of the tessellation (``gather_weighted.cl``) against its numpy reference (tier: opencl)."""

import numpy as np
import pytest
from tessera.kernels.common.tolerances import FLOAT32_PATH_ATOL, FLOAT32_PATH_RTOL
from tessera.kernels.common.topology import triangle_edges
from tessera.kernels.tessellation import interpolate
from tessera.kernels.tessellation.refine import refine
from tessera.tools.generators import random_closed

pytestmark = pytest.mark.opencl




@pytest.mark.parametrize("channels, taps", [(1, 2), (3, 3), (4, 3), (2, 5)])
def test_gather_matches_numpy(opencl, channels, taps):
    rng = np.random.default_rng(channels * 10 + taps)
    values = rng.normal(size=(5000, channels)).astype(np.float32)
    idx = rng.integers(0, len(values), size=(70_000, taps))
    weights = rng.dirichlet(np.ones(taps), size=len(idx))
    ref = interpolate.gather_weighted_numpy(values, idx, weights)
    out = interpolate.gather_weighted_opencl(opencl, values, idx, weights)
    assert out.dtype == np.float32 and out.shape == ref.shape
    np.testing.assert_allclose(out, ref, rtol=FLOAT32_PATH_RTOL, atol=FLOAT32_PATH_ATOL)


def test_refined_positions_match_numpy(opencl):
    v, f = random_closed(11, 40, 30)
    ref = refine(f, len(v), np.full(len(triangle_edges(f)[0]), 6.0))
    a = interpolate.point_values(ref, v, backend="numpy")
    b = interpolate.point_values(ref, v, backend="opencl")
    np.testing.assert_allclose(b, a, rtol=FLOAT32_PATH_RTOL, atol=FLOAT32_PATH_ATOL)
    assert np.array_equal(a[: ref.n_corners], b[: ref.n_corners])  # input vertices are copied exactly


def test_opencl_corner_values_agree_bit_for_bit_at_shared_vertices(opencl):
    from test_tessellate import continuous_uvs, one_value_per_vertex

    v, f, uv = continuous_uvs(5)
    levels = np.random.default_rng(3).uniform(1, 12, len(triangle_edges(f)[0]))
    ref = refine(f, len(v), levels, spacing="FRACTIONAL_EVEN")
    assert ref.face_class is None and len(ref.triangles) * 3 >= interpolate.OPENCL_MIN_ROWS  # the gather path
    out = interpolate.corner_values(ref, uv[f], backend="opencl")
    assert one_value_per_vertex(ref.triangles, out)
    reference = interpolate.corner_values(ref, uv[f], backend="numpy")
    np.testing.assert_allclose(out, reference, rtol=FLOAT32_PATH_RTOL, atol=FLOAT32_PATH_ATOL)


def test_empty_gather(opencl):
    out = interpolate.gather_weighted_opencl(opencl, np.zeros((3, 2), np.float32), np.zeros((0, 3), int),
                                             np.zeros((0, 3)))
    assert out.shape == (0, 2)

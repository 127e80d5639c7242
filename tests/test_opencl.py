"""OpenCL kernels against their numpy references (tier: opencl; PoCL in CI)."""

import numpy as np
import pytest
from meshes import random_closed
from tessera.kernels import interpolate, opencl_runtime
from tessera.kernels.errors import TesseraError
from tessera.kernels.refine import refine
from tessera.kernels.tolerances import FLOAT32_PATH_ATOL, FLOAT32_PATH_RTOL
from tessera.kernels.topology import triangle_edges

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


def test_empty_gather(opencl):
    out = interpolate.gather_weighted_opencl(opencl, np.zeros((3, 2), np.float32), np.zeros((0, 3), int),
                                             np.zeros((0, 3)))
    assert out.shape == (0, 2)


def test_build_error_reports_the_compiler_log(opencl, monkeypatch):
    monkeypatch.setitem(opencl_runtime._sources, "broken", "__kernel void k(__global float *x) { x[0] = y; }")
    with pytest.raises(TesseraError, match="failed to build") as err:
        opencl.program("broken")
    assert "y" in str(err.value)


@pytest.mark.parametrize("caps", ["NONE", "ROUND"])
def test_tube_kernels_equal_the_numpy_reference(opencl, caps):
    from tessera.kernels.polylines import Polylines
    from tessera.kernels.tubes import TubeSettings, build_tubes

    rng = np.random.default_rng(12)
    counts = rng.integers(2, 90, size=300)
    pts = np.cumsum(rng.normal(size=(counts.sum(), 3)), axis=0)
    lines = Polylines.build(pts, np.concatenate(([0], np.cumsum(counts))), radius=rng.uniform(0.1, 0.3, len(pts)),
                            tilt=rng.uniform(-1, 1, len(pts)), cyclic=rng.random(300) < 0.3,
                            material_index=rng.integers(0, 4, 300))
    settings = TubeSettings(sides=7, caps=caps)
    a = build_tubes(lines, settings, backend="opencl")
    b = build_tubes(lines, settings, backend="numpy")
    for name in ("face_sizes", "corner_verts", "corner_edges", "edges", "face_material"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    scale = np.abs(pts).max()
    assert np.allclose(a.positions, b.positions, atol=1e-6 * scale)
    assert np.allclose(a.point_normals, b.point_normals, atol=1e-5)
    assert np.allclose(a.corner_uvs, b.corner_uvs, atol=1e-6)

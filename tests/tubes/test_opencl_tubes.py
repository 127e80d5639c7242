"""OpenCL tube kernels (``tube_frames.cl``, ``tube_body.cl``) against the numpy reference (tier: opencl)."""

import numpy as np
import pytest

pytestmark = pytest.mark.opencl




@pytest.mark.parametrize("caps", ["NONE", "ROUND"])
def test_tube_kernels_equal_the_numpy_reference(opencl, caps):
    from tessera.kernels.tubes.builder import TubeSettings, build_tubes
    from tessera.kernels.tubes.polylines import Polylines

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

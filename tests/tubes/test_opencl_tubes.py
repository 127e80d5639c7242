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


@pytest.mark.parametrize("caps", ["NONE", "FLAT", "ROUND"])
def test_tubes_without_point_normals_are_the_same_mesh(opencl, caps):
    """Leaving out the radial point normals (what the operator does: Blender derives the mesh's normals) changes
    nothing else, on both backends: the same bytes for positions, topology, UVs and FLAT caps' corner normals."""
    from tessera.kernels.tubes.builder import TubeSettings, build_tubes
    from tessera.kernels.tubes.polylines import Polylines

    rng = np.random.default_rng(5)
    counts = rng.integers(2, 60, size=200)
    pts = np.cumsum(rng.normal(size=(counts.sum(), 3)), axis=0)
    lines = Polylines.build(pts, np.concatenate(([0], np.cumsum(counts))), radius=rng.uniform(0.1, 0.3, len(pts)),
                            cyclic=rng.random(200) < 0.3, material_index=rng.integers(0, 4, 200))
    for backend in ("opencl", "numpy"):
        full = build_tubes(lines, TubeSettings(sides=6, caps=caps), backend=backend)
        lean = build_tubes(lines, TubeSettings(sides=6, caps=caps, point_normals=False), backend=backend)
        assert lean.point_normals is None and (full.point_normals is None) == (caps == "FLAT")
        for name in ("positions", "face_sizes", "corner_verts", "corner_edges", "edges", "face_material",
                     "corner_uvs", "corner_normals"):
            a, b = getattr(lean, name), getattr(full, name)
            assert (a is None) == (b is None), name
            assert a is None or np.array_equal(a, b), (backend, name)

"""The OpenCL Loop levels (``loop_level.cl``) against the numpy reference (tier: opencl): the same topology, bit for
bit, and the same values within float64 rounding; semi-sharp creases stay on numpy."""

import numpy as np
import pytest
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.subdivision.loop import loop_subdivide
from tessera.kernels.subdivision.loop_topology import coarse_level
from tessera.tools.generators import (
    bipyramid,
    cup,
    icosahedron,
    octahedron,
    plane_with_hole,
    random_irregular_closed,
    torus,
)

pytestmark = pytest.mark.opencl

MESHES = {
    "octahedron": octahedron, "icosahedron": icosahedron, "bipyramid16": lambda: bipyramid(16),
    "torus": lambda: torus(12, 7), "irregular": lambda: random_irregular_closed(4), "cup": cup,
    "plane_with_hole": plane_with_hole,
}


def same(a, b, scale):
    for name in ("triangles", "edges", "corner_edges", "edge_sharpness"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert np.abs(a.positions - b.positions).max() <= 1e-13 * scale


@pytest.mark.parametrize("boundary", ["EDGE_ONLY", "EDGE_AND_CORNER"])
@pytest.mark.parametrize("name", list(MESHES))
def test_levels_equal_the_numpy_reference(opencl, name, boundary):
    v, f = MESHES[name]()
    scale = float(np.abs(v).max())
    for level in (1, 2, 3, 4):
        a = loop_subdivide(v, f, level, boundary=boundary, backend="opencl", dtype=np.float64)
        b = loop_subdivide(v, f, level, boundary=boundary, backend="numpy", dtype=np.float64)
        same(a, b, scale)


def test_sharp_creases_corners_and_corner_data(opencl):
    rng = np.random.default_rng(3)
    v, f = random_irregular_closed(9)
    edges = coarse_level(f, len(v)).edges
    creases = edges[rng.choice(len(edges), 12, replace=False)], np.full(12, 10.0, np.float32)
    vs = np.zeros(len(v), np.float32)
    vs[[1, 4]] = 10.0
    uv = rng.random((len(f), 3, 2))  # every corner its own value: all seams
    col = rng.random((len(v), 4))[f]  # corner colours without seams
    kw = {"creases": creases, "vertex_sharpness": vs, "point_data": {"w": v[:, 0] ** 2},
          "corner_data": {"UV": uv, "Col": col}, "dtype": np.float64}
    for level in (1, 3):
        a = loop_subdivide(v, f, level, backend="opencl", **kw)
        b = loop_subdivide(v, f, level, backend="numpy", **kw)
        same(a, b, float(np.abs(v).max()))
        assert np.abs(a.point_attributes["w"] - b.point_attributes["w"]).max() <= 1e-13
        for name in ("UV", "Col"):
            assert np.abs(a.corner_attributes[name] - b.corner_attributes[name]).max() <= 1e-13, name


def test_semi_sharp_creases_stay_on_numpy(opencl):
    v, f = random_irregular_closed(2)
    edges = coarse_level(f, len(v)).edges
    creases = edges[:5], np.full(5, 1.5, np.float32)
    with pytest.raises(InvalidInputError, match="semi-sharp"):
        loop_subdivide(v, f, 2, creases=creases, backend="opencl")
    a = loop_subdivide(v, f, 4, creases=creases, backend="auto", dtype=np.float64)
    b = loop_subdivide(v, f, 4, creases=creases, backend="numpy", dtype=np.float64)
    assert np.array_equal(a.positions, b.positions)  # auto took numpy: the same bits

"""The recomputation model ([Concheiro et al.]): each coarse triangle subdivided from its 1-ring
alone gives, bit for bit, what its neighbours give on shared vertices and what the whole-mesh reference gives,
whatever the order the triangles are taken in."""

import numpy as np
import pytest
from tessera.kernels.subdivision.loop import loop_subdivide
from tessera.kernels.subdivision.loop_recompute import Recomputation, one_ring
from tessera.kernels.subdivision.loop_topology import coarse_level
from tessera.tools.generators import bipyramid, cup, plane_with_hole, random_irregular_closed

pytestmark = pytest.mark.usefixtures("numpy_reference")  # the numpy reference; OpenCL is compared elsewhere


MESHES = {"irregular": lambda: random_irregular_closed(5), "bipyramid16": lambda: bipyramid(16), "cup": cup,
          "plane_with_hole": plane_with_hole}


@pytest.mark.parametrize("boundary", ["EDGE_ONLY", "EDGE_AND_CORNER"])
@pytest.mark.parametrize("name", list(MESHES))
def test_per_triangle_equals_the_whole_mesh_bit_for_bit(name, boundary):
    v, f = MESHES[name]()
    for level in (1, 2, 3):
        ref = loop_subdivide(v, f, level, boundary=boundary, dtype=np.float64)
        rec = Recomputation(v, f, level, boundary=boundary).run(check=True)  # shared vertices: the same bits
        assert np.array_equal(rec, ref.positions)


def test_creases_and_any_dispatch_order():
    rng = np.random.default_rng(7)
    v, f = random_irregular_closed(6)
    edges = coarse_level(f, len(v)).edges
    pick = rng.choice(len(edges), 10, replace=False)
    creases = edges[pick], rng.choice([10.0, 0.5, 1.5, 2.5], 10).astype(np.float32)
    vs = np.zeros(len(v), np.float32)
    vs[3] = 1.5
    ref = loop_subdivide(v, f, 3, creases=creases, vertex_sharpness=vs, dtype=np.float64)
    rec = Recomputation(v, f, 3, creases=creases, vertex_sharpness=vs)
    for order in (None, rng.permutation(len(f)), np.arange(len(f))[::-1]):
        assert np.array_equal(rec.run(order), ref.positions)


def test_the_patch_is_the_one_ring():
    """n0 + n1 + n2 - 6 triangles around each triangle of a closed mesh ([Concheiro et al.]), and nothing else moves
    a triangle's sub-triangles."""
    v, f = random_irregular_closed(3)
    valence = np.bincount(f.ravel())
    rings = one_ring(f, len(v))
    assert all(len(rings[t]) - 1 == valence[f[t]].sum() - 6 for t in range(len(f)))  # itself excluded
    rec = Recomputation(v, f, 2)
    t = 5
    ids, values = rec.patch(t)
    outside = np.setdiff1d(np.arange(len(v)), np.unique(f[rings[t]]))
    moved = v.copy()
    moved[outside] += 10.0
    ids2, values2 = Recomputation(moved, f, 2).patch(t)
    assert np.array_equal(ids, ids2) and np.array_equal(values, values2)

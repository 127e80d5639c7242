"""Per-coarse-triangle stencils ([Concheiro et al.]'s one-invocation-per-triangle model): numpy and OpenCL evaluations
equal the reference, every triangle writes the shared vertices with the same bits, and the weights do not depend on
positions."""

import numpy as np
import pytest
from tessera.kernels.subdivision import loop_stencils
from tessera.kernels.subdivision.loop import loop_subdivide
from tessera.kernels.subdivision.loop_topology import coarse_level
from tessera.tools.generators import bipyramid, cup, random_irregular_closed

MESHES = {"irregular": lambda: random_irregular_closed(2), "bipyramid16": lambda: bipyramid(16), "cup": cup}


@pytest.mark.usefixtures("numpy_reference")
@pytest.mark.parametrize("name", list(MESHES))
def test_stencils_equal_the_reference_and_agree_on_shared_vertices(name):
    v, f = MESHES[name]()
    for level in (1, 2, 3):
        table = loop_stencils.build(v, f, level)
        ref = loop_subdivide(v, f, level, dtype=np.float64)
        assert np.array_equal(table.triangles, ref.triangles)
        out = loop_stencils.apply(table, v)
        assert np.abs(out - ref.positions).max() <= 1e-14 * np.abs(v).max()
        # every triangle's own rows: shared vertices get the same bits from each writer
        rows = np.einsum("fkp,fpd->fkd", table.weights[table.stencil],
                         np.where((table.patch >= 0)[..., None], v[np.maximum(table.patch, 0)], 0.0))
        assert np.array_equal(rows, out[table.outputs])
        # the stencils are the same for any positions
        moved = v + np.random.default_rng(level).normal(size=v.shape)
        assert np.abs(loop_stencils.apply(table, moved) -
                      loop_subdivide(moved, f, level, dtype=np.float64).positions).max() <= 1e-13


@pytest.mark.usefixtures("numpy_reference")
def test_creases_in_the_stencils():
    v, f = random_irregular_closed(4)
    edges = coarse_level(f, len(v)).edges
    creases = edges[::6], np.full(len(edges[::6]), 1.5, np.float32)
    table = loop_stencils.build(v, f, 2, creases=creases)
    ref = loop_subdivide(v, f, 2, creases=creases, dtype=np.float64)
    assert np.abs(loop_stencils.apply(table, v) - ref.positions).max() <= 1e-14


@pytest.mark.opencl
@pytest.mark.parametrize("name", list(MESHES))
def test_one_work_item_per_coarse_triangle_on_opencl(opencl, name):
    v, f = MESHES[name]()
    for level in (1, 2, 3):
        table = loop_stencils.build(v, f, level)
        device = loop_stencils.apply_opencl(opencl, table, v)
        assert np.array_equal(device, loop_stencils.apply(table, v))
        ref = loop_subdivide(v, f, level, backend="numpy", dtype=np.float64)
        assert np.abs(device - ref.positions).max() <= 1e-14 * np.abs(v).max()

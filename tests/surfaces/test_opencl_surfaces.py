"""Tessellate Surface's measuring on an OpenCL device (``patch_deviation.cl``) against the numpy reference (tier:
opencl): the inner grids' deviations, the triangles' and the surface points agree to float64 rounding on random
rational patches of every degree, and whole tessellations at a Tolerance give the same levels and the same mesh."""

import numpy as np
import pytest
from tessera.kernels.common.curves import nurbs, step_spacing
from tessera.kernels.surfaces import bezier_patches as bp
from tessera.kernels.surfaces import patch_deviation_opencl as pd
from tessera.kernels.surfaces.bezier_patches import deviation

from tools.utah_teapot import teapot_patches

pytestmark = pytest.mark.opencl


def random_nets(rng, count, k):
    """(count, k, k, 4) homogeneous nets: bumpy control points, weights 0.3-3."""
    base = np.stack(np.meshgrid(np.linspace(0, 1, k), np.linspace(0, 1, k), indexing="ij"), -1)
    xyz = np.concatenate([np.broadcast_to(base, (count, k, k, 2)), rng.uniform(-.3, .3, (count, k, k, 1))], -1)
    xyz = xyz + rng.normal(0, .05, xyz.shape)
    w = rng.uniform(0.3, 3.0, (count, k, k, 1))
    return np.concatenate([xyz * w, w], -1)


def bumpy_sphere(rng):
    """A NURBS sphere with its poles (collapsed rows), random weights, cyclic around: 8 x 6 points, order 4."""
    ang = np.arange(8) / 8 * 2 * np.pi
    lat = np.linspace(-np.pi / 2, np.pi / 2, 6)
    pts = np.stack([np.cos(lat)[:, None] * np.cos(ang)[None], np.cos(lat)[:, None] * np.sin(ang)[None],
                    np.broadcast_to(np.sin(lat)[:, None], (6, 8))], -1)
    w = rng.uniform(0.5, 2.0, (6, 8, 1))
    w[0], w[-1] = w[0, 0], w[-1, 0]  # one weight a pole: one point
    spline = nurbs.SurfaceSpline(np.concatenate([pts, w], -1), nurbs.Direction(4, "UNIFORM", True),
                                 nurbs.Direction(4, "ENDPOINT"))
    return nurbs.patches_of([spline]).patches


@pytest.mark.parametrize("k", [2, 3, 4, 5, 6, 7])
def test_grids_triangles_and_points_equal_the_numpy_reference(opencl, k):
    rng = np.random.default_rng(k)
    h = random_nets(rng, 9, k)
    scale = float(np.abs(bp.cartesian(h)).max())
    n_in = rng.integers(3, 20, (9, 2))
    n_in[0] = (2, 7)  # fewer than 3 steps one way: no grid measured
    edges = bp.patch_edges(h)
    spacing = bp.patch_spacing(h, edges)
    for points in (deviation._B, deviation._B[:4]):
        for sp in (None, spacing):
            ref = bp.grid_deviation(h, n_in, sp, points=points)
            got = bp.grid_deviation(h, n_in, sp, points=points, runtime=opencl)
            assert (got[0] == 0).all() and (ref[1:, 0] > 0).all()
            assert np.abs(got - ref).max() <= 1e-12 * scale
    # triangles one by one: every triangle of a random cut of random patches
    t = 500
    patch = rng.integers(0, len(h), t)
    uv = rng.uniform(0, 1, (t, 3, 2))
    corners = bp.evaluate(h[patch], uv[..., 0], uv[..., 1]) + rng.normal(0, 1e-3, (t, 3, 3))
    ref = deviation._deviation(h, corners, uv, patch)
    assert np.abs(deviation._deviation(h, corners, uv, patch, opencl) - ref).max() <= 1e-12 * scale
    flat = uv.reshape(-1, 2)
    on = bp.evaluate(h[np.repeat(patch, 3)], flat[:, :1], flat[:, 1:])[:, 0]
    assert np.abs(pd.points(opencl, h, flat, np.repeat(patch, 3)) - on).max() <= 1e-12 * scale


def test_launches_split_into_chunks_give_the_same_grids(opencl, monkeypatch):
    rng = np.random.default_rng(7)
    h = random_nets(rng, 12, 4)
    n_in = rng.integers(3, 30, (12, 2))
    t = [step_spacing.padded_params(np.array([[0.0, 1.0]]).repeat(12, 0), n_in[:, a]) for a in (0, 1)]
    whole = pd.grid_deviation(opencl, h, n_in, *t, deviation._B)
    monkeypatch.setattr(pd, "CHUNK", 50)  # smaller than some patches' grids: those launch alone
    assert np.array_equal(pd.grid_deviation(opencl, h, n_in, *t, deviation._B), whole)


@pytest.mark.parametrize("model", ["teapot", "sphere", "random"])
def test_tessellations_measured_on_the_device_equal_the_numpy_ones(opencl, model):
    rng = np.random.default_rng(11)
    h = {"teapot": lambda: bp.check_patches(teapot_patches()[0]), "sphere": lambda: bumpy_sphere(rng),
         "random": lambda: random_nets(rng, 6, 5)}[model]()
    size = float(np.abs(bp.cartesian(h)).max())
    lod = bp.PatchLod(metrics=("TOLERANCE",), tolerance=5e-4 * size, max_level=64)
    a, b = bp.tessellate_surface(h, lod, backend="numpy"), bp.tessellate_surface(h, lod, backend="opencl")
    assert np.array_equal(a.edge_levels, b.edge_levels) and np.array_equal(a.inner_levels, b.inner_levels)
    assert np.array_equal(a.mesh.triangles, b.mesh.triangles)
    assert np.array_equal(a.mesh.positions, b.mesh.positions)
    assert np.abs(a.deviation - b.deviation).max() <= 1e-12 * size
    assert len(b.unmet) == 0 and b.deviation.max() <= lod.tolerance



def test_tessellations_on_many_threads_share_the_device(opencl):
    from tessera.kernels.common import workers

    h = bp.check_patches(teapot_patches()[0])
    lod = bp.PatchLod(metrics=("TOLERANCE",), tolerance=2e-3, max_level=64)
    here = bp.tessellate_surface(h, lod, backend="opencl")
    # the same kernel objects launched from every worker at once: each launch's arguments are its own
    there = [workers.submit(bp.tessellate_surface, h, lod, None, None, "opencl") for _ in range(workers.WORKERS + 1)]
    for future in there:
        r = future.result(timeout=120)
        assert np.array_equal(r.mesh.positions, here.mesh.positions)
        assert np.array_equal(r.deviation, here.deviation)


def test_a_program_the_device_refuses_leaves_the_measuring_to_numpy(opencl, monkeypatch, caplog):
    from tessera.kernels.common.errors import TesseraError

    def refuse(runtime, k):
        raise TesseraError("OpenCL program surfaces/patch_deviation.cl failed to build: (a driver's log)")

    monkeypatch.setattr(pd, "build", refuse)
    bp._log_once.cache_clear()
    h = bp.check_patches(teapot_patches()[0][:4])
    lod = bp.PatchLod(metrics=("TOLERANCE",), tolerance=1e-3)
    with caplog.at_level("WARNING"):
        r = bp.tessellate_surface(h, lod)  # auto: numpy, said once
        bp.tessellate_surface(h, lod)
    assert sum("with numpy" in m for m in caplog.messages) == 1
    assert np.array_equal(r.mesh.positions, bp.tessellate_surface(h, lod, backend="numpy").mesh.positions)
    with pytest.raises(TesseraError, match="failed to build"):
        bp.tessellate_surface(h, lod, backend="opencl")

"""The GPU terrain preview (instanced tile patterns, heights sampled in the vertex shader) against the numpy
bake, and the crack test (tier: gpu)."""

import numpy as np
import pytest

pytestmark = [pytest.mark.blender, pytest.mark.gpu]


def terrain(addon_module, size=193):
    """``size`` rows of ``size - 8`` samples: with tiles of 32, the last column of tiles is 24 texels wide (partial
    tiles, whose inner grids are longer along y than along x at the top levels)."""
    hio = addon_module("kernels.terrain.heightmap_io")
    y, x = np.mgrid[0:size, 0:size - 8] / (size - 1)
    h = 25 * np.sin(7 * x) * np.cos(5 * y) + 12 * np.sin(19 * x * y)
    h[(x - 0.6) ** 2 + (y - 0.4) ** 2 < 0.02] += 18.0  # a mesa with cliffs
    h[:, : size // 5] = 0.0
    return hio.from_array(h.astype(np.float32), texel_size=1.0)


def _scene(addon_module):
    """Modules, the test terrain, its tile table and preview data."""
    ta, tl, tm = (addon_module(f"kernels.terrain.{m}") for m in ("analysis", "lod", "mesh"))
    hm = terrain(addon_module)
    table = ta.tile_table(hm, 32, backend="numpy")
    data = addon_module("gpu_shaders.terrain.draw").TerrainDrawData(hm, table)
    return (tl, tm, addon_module("gpu_shaders.offscreen"), addon_module("kernels.common.camera").Camera, hm, table,
            data)


def cameras(Camera, rng, n):
    for _ in range(n):
        a = rng.uniform(0, 2 * np.pi)
        eye = (220 * np.cos(a), 220 * np.sin(a), rng.uniform(40, 160))
        yield Camera.looking_at(eye, (rng.uniform(-40, 40), rng.uniform(-40, 40), 0), fov_deg=45, width=200,
                                height=200, far=2000)


@pytest.mark.parametrize("levels, mode", [("POW2", "OURS"), ("FRACTIONAL", "OURS"), ("INTEGER", "UNIFORM")])
def test_preview_draws_the_baked_mesh(gpu_renderer, addon_module, levels, mode):
    tl, tm, offscreen, Camera, hm, table, data = _scene(addon_module)
    for cam in cameras(Camera, np.random.default_rng(2), 3):
        sel = tl.select(hm, table, cam, tl.TerrainLod(levels=levels, mode=mode))
        if mode == "UNIFORM":
            assert sel.inner_y is not None  # the partial tiles' rectangular inner grids are drawn
        mesh = tm.bake(hm, table, sel)
        vp = cam.projection @ cam.view
        cpu = offscreen.render_triangles(mesh.positions, mesh.triangles, vp, size=(200, 200), color=(1, 1, 1, 1),
                                         lit=False)
        data.set_selection(sel)
        gpu = offscreen.render(lambda vp=vp: data.draw(vp, color=(1, 1, 1, 1), lit=False), size=(200, 200))
        a, b = cpu[..., 0] > 127, gpu[..., 0] > 127
        assert 4000 < a.sum() < a.size - 4000  # terrain and sky both in view: ridges make the outline
        assert np.mean(a == b) >= 0.995, np.mean(a == b)
        assert data.tile_bytes == 48 * int((~sel.culled).sum())


def test_preview_has_no_cracks_from_random_cameras(gpu_renderer, addon_module):
    """Flat white terrain over black, seen from above: no black pixel where the baked mesh (welded, shown
    watertight by the kernel tests) covers the view, eroded by a pixel so outline rasterisation does not count."""
    tl, tm, offscreen, Camera, hm, table, data = _scene(addon_module)
    rng = np.random.default_rng(5)
    for levels in ("FRACTIONAL", "INTEGER"):
        for _ in range(10):
            eye = np.append(rng.uniform(-30, 30, 2), rng.uniform(150, 260))
            cam = Camera.looking_at(eye, (rng.uniform(-10, 10), rng.uniform(-10, 10), 0), fov_deg=40, width=160,
                                    height=160, far=2000, up=(0, 1, 0))
            sel = tl.select(hm, table, cam, tl.TerrainLod(levels=levels, culling=False))
            data.set_selection(sel)
            img = offscreen.render(lambda cam=cam: data.draw(cam.projection @ cam.view, color=(1, 1, 1, 1), lit=False),
                                   size=(160, 160))
            mesh = tm.bake(hm, table, sel)
            ref = offscreen.render_triangles(mesh.positions, mesh.triangles, cam.projection @ cam.view,
                                             size=(160, 160), color=(1, 1, 1, 1), lit=False)[..., 0] > 127
            p = np.pad(ref, 1, mode="edge")
            inside = p[1:-1, 1:-1] & p[:-2, 1:-1] & p[2:, 1:-1] & p[1:-1, :-2] & p[1:-1, 2:]
            white = img[..., 0] > 127
            assert inside.sum() > 5000
            assert not (inside & ~white).any(), int((inside & ~white).sum())

"""The Loop preview (tier: gpu): it draws the kernel's mesh, with the baked colours, where the mesh is."""

import numpy as np
import pytest
from tessera.tools.generators import cup, random_irregular_closed

pytestmark = [pytest.mark.blender, pytest.mark.gpu]


def test_preview_draws_the_kernels_mesh(clean_scene, bpy_module, addon_module, gpu_renderer):
    bpy = bpy_module
    preview = addon_module("addon.subdivision.preview")
    offscreen = addon_module("gpu_shaders.offscreen")
    Camera = addon_module("kernels.common.camera").Camera
    bpy.ops.mesh.primitive_monkey_add()
    ob = bpy.context.active_object
    ob.tessera.loop.levels = 2
    data = preview.build_draw_data(ob)
    assert bpy.ops.tessera.loop_subdivide(levels=2) == {"FINISHED"}
    out = bpy.context.active_object.data
    pos = np.empty(len(out.vertices) * 3, np.float32)
    out.attributes["position"].data.foreach_get("vector", pos)
    assert np.array_equal(data.positions, pos.reshape(-1, 3)) and len(data.triangles) == len(out.polygons)
    cam = Camera.looking_at((0.5, -4.0, 1.0), (0, 0, 0), width=160, height=160)
    image = offscreen.render(lambda: data.draw(cam.projection @ cam.view), size=(160, 160))
    cpu = offscreen.render_triangles(data.positions, data.triangles, cam.projection @ cam.view, size=(160, 160),
                                     color=(1, 1, 1, 1), lit=False)
    drawn, expect = image[..., :3].max(axis=2) > 0, cpu[..., 0] > 127
    assert expect.sum() > 3000 and np.mean(drawn == expect) > 0.99


def test_preview_shows_the_baked_colours(clean_scene, bpy_module, addon_module, gpu_renderer):
    bpy = bpy_module
    preview = addon_module("addon.subdivision.preview")
    hce = addon_module("kernels.subdivision.hce")
    bridge = addon_module("addon.bridge")
    offscreen = addon_module("gpu_shaders.offscreen")
    Camera = addon_module("kernels.common.camera").Camera
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=1)
    ob = bpy.context.active_object
    arrays, _ = bridge.read_mesh(ob.data)
    red = hce.HceTree(np.zeros((0, 3), np.float32), np.array([[[1.0, 0.0, 0.0, 1.0]]], np.float32),
                      np.array([False]))
    ob.data["tessera_hce"] = hce.pack_container([red] * len(arrays.triangles), arrays.triangles, 4)
    data = preview.build_draw_data(ob)
    assert data.baked and np.allclose(data.colours, [1, 0, 0, 1])
    cam = Camera.looking_at((0, -4.0, 0), (0, 0, 0), width=96, height=96)
    image = offscreen.render(lambda: data.draw(cam.projection @ cam.view), size=(96, 96))
    red_pixels = (image[..., 0] > 240) & (image[..., 1] < 10) & (image[..., 2] < 10)
    assert red_pixels[48, 48]  # the baked colour, drawn as it is (not shaded)
    assert red_pixels.sum() > 1000


def test_compute_shader_one_invocation_per_coarse_triangle(gpu_renderer, addon_module):
    """The stencils in a Blender compute shader equal the numpy reference (float32 on the GPU)."""
    stencils = addon_module("kernels.subdivision.loop_stencils")
    loop = addon_module("kernels.subdivision.loop")
    draw = addon_module("gpu_shaders.subdivision.draw")
    for v, f in (random_irregular_closed(3), cup()):
        for level in (1, 2, 3):
            table = stencils.build(v, f, level)
            gpu = draw.evaluate_stencils_on_gpu(table, v.astype(np.float32))
            ref = loop.loop_subdivide(v, f, level, backend="numpy", dtype=np.float64).positions
            assert np.abs(gpu - ref).max() <= 1e-6 * max(1.0, np.abs(ref).max())

"""GPU context and offscreen rendering against the CPU result (tier: gpu; Mesa llvmpipe in CI)."""

import numpy as np
import pytest

pytestmark = [pytest.mark.blender, pytest.mark.gpu]


def test_context_and_renderer(gpu_renderer, addon_module):
    assert gpu_renderer
    assert addon_module("addon.gpu_context").has_gpu_context()


def test_linear_tessellation_renders_like_the_original(gpu_renderer, addon_module, clean_scene, bpy_module):
    """Linear tessellation must not change the picture: same silhouette, same flat shading."""
    bpy = bpy_module
    bridge = addon_module("addon.bridge")
    tess = addon_module("kernels.tessellation.tessellate")
    look_at = addon_module("kernels.common.camera").look_at
    render = addon_module("gpu_shaders.offscreen").render_triangles
    bpy.ops.mesh.primitive_monkey_add()
    arrays, _ = bridge.read_mesh(bpy.context.active_object.data)
    out = tess.tessellate(arrays, tess.uniform_levels(arrays, 5), backend="numpy").mesh
    rng = np.random.default_rng(5)
    for _ in range(3):
        direction = rng.normal(size=3)
        eye = 4.0 * direction / np.linalg.norm(direction)
        vp = look_at(eye, (0, 0, 0))
        a = render(arrays.positions, arrays.triangles, vp, size=(160, 160))
        b = render(out.positions, out.triangles, vp, size=(160, 160))
        assert (a[..., 0] > 0).sum() > 1000  # the mesh is in view
        close = np.all(np.abs(a.astype(int) - b.astype(int)) <= 2, axis=-1)
        assert close.mean() >= 0.995


def test_flat_colour_mode_is_exact(gpu_renderer, addon_module):
    render = addon_module("gpu_shaders.offscreen").render_triangles
    look_at = addon_module("kernels.common.camera").look_at
    pos = np.array([[-1, -1, 0], [1, -1, 0], [0, 1, 0]], np.float32)
    img = render(pos, np.array([[0, 1, 2]]), look_at((0, 0, 4), (0, 0, 0), up=(0, 1, 0)), size=(64, 64),
                 color=(1, 0, 0, 1), lit=False)
    inside = img[..., 0] == 255
    assert inside.sum() > 300 and np.all(img[inside][:, 1:3] == 0)
    assert img[2, 2, 0] == 0  # a corner pixel is background

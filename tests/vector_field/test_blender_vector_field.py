"""``tessera.vector_field_texture`` (tier: blender): the image it packs is the kernel's, on the CPU exactly and on the
GPU within the rasteriser's snapping; a grid mesh's point attribute is a field, a missing one is refused."""

import numpy as np
import pytest

pytestmark = pytest.mark.blender


@pytest.mark.parametrize("backend", ["CPU", "GPU"])
def test_vector_field_texture_writes_the_kernels_image(clean_scene, bpy_module, addon_module, backend):
    bpy = bpy_module
    fields = addon_module("kernels.vector_field.fields")
    streaks = addon_module("kernels.vector_field.streaks")
    if backend == "GPU":
        addon_module("addon.gpu_context").ensure_gpu_context()
    before = set(bpy.data.images)
    kw = {"field": "VORTEX", "width": 48, "height": 40, "seeds": 40, "steps": 12, "step": 0.003, "backend": backend}
    assert bpy.ops.tessera.vector_field_texture(**kw) == {"FINISHED"}
    [image] = set(bpy.data.images) - before
    assert tuple(image.size) == (48, 40) and image.packed_file is not None
    px = np.empty(48 * 40 * 4, np.float32)
    image.pixels.foreach_get(px)
    grey = px.reshape(40, 48, 4)[..., 0]
    # no scene camera: the sparsest lattice, the operator's own seeds
    want = streaks.streak_image(fields.AnalyticField("VORTEX"), 48, 40, 40, 0.003, 12, seed=0)
    tol = 1e-6 if backend == "CPU" else 0.08  # the GPU's rasteriser moves ~1% of the splats by a pixel
    assert np.abs(grey - want).mean() <= tol


def test_vector_field_from_a_grid_mesh(clean_scene, bpy_module):
    bpy = bpy_module
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=8, y_subdivisions=6, size=2)
    ob = bpy.context.active_object
    n = len(ob.data.vertices)
    attr = ob.data.attributes.new("velocity", "FLOAT_VECTOR", "POINT")
    co = np.array([v.co for v in ob.data.vertices])
    attr.data.foreach_set("vector", np.c_[-co[:, 1], co[:, 0], np.zeros(n)].astype(np.float32).ravel())
    assert bpy.ops.tessera.vector_field_texture(field="MESH", width=32, height=32, seeds=16, steps=5,
                                                backend="CPU") == {"FINISHED"}
    with pytest.raises(RuntimeError, match="no vector point attribute named 'wind'"):
        bpy.ops.tessera.vector_field_texture(field="MESH", attribute="wind", backend="CPU")

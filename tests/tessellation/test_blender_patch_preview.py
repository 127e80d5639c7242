"""The live tessellation preview as the add-on runs it (settings on the object, level updates, depsgraph) and
the operator's compute-shader path (tier: gpu)."""

import numpy as np
import pytest
from blender_helpers import compat, refuses_tangent_space

pytestmark = [pytest.mark.blender, pytest.mark.gpu]


def _monkey(bpy):
    bpy.ops.mesh.primitive_monkey_add(location=(0.5, 0.0, 0.2), rotation=(0.3, 0.0, 0.5))
    ob = bpy.context.active_object
    for poly in ob.data.polygons:
        poly.use_smooth = True
    return ob


def _view(Camera, eye):
    return Camera.looking_at(eye, (0.5, 0.0, 0.2), fov_deg=40, width=200, height=200, far=100)


def test_preview_follows_settings_view_and_edits(gpu_renderer, addon_module, clean_scene, bpy_module):
    from mathutils import Matrix

    bpy = bpy_module
    preview = addon_module("addon.tessellation.preview")
    offscreen = addon_module("gpu_shaders.offscreen")
    Camera = addon_module("kernels.common.camera").Camera
    ob = _monkey(bpy)
    s = ob.tessera.tessellate
    s.method, s.level_mode, s.metrics, s.max_level, s.spacing = "PN", "ADAPTIVE", {"PROJECTED"}, 10.0, "EQUAL"
    s.preview = True
    cam = _view(Camera, (4.0, -3.0, 2.0))
    entry = preview.entry_for(ob)
    assert preview.update_levels(ob, entry, cam.view, cam.projection, 200, 200)
    assert not preview.update_levels(ob, entry, cam.view, cam.projection, 200, 200)  # nothing changed: no work
    model = np.array(ob.matrix_world)
    vp = cam.projection @ cam.view @ model
    gpu_img = offscreen.render(lambda: entry.draw.draw(vp), size=(200, 200))
    # the operator with the same settings, for the scene camera at the same place
    cam_data = bpy.data.cameras.new("cam")
    cam_ob = bpy.data.objects.new("cam", cam_data)
    bpy.context.scene.collection.objects.link(cam_ob)
    cam_ob.matrix_world = Matrix(np.linalg.inv(cam.view).tolist())
    cam_data.angle = np.radians(40)
    scene = bpy.context.scene
    scene.camera = cam_ob
    scene.render.resolution_x = scene.render.resolution_y = 200
    scene.render.resolution_percentage = 100
    bpy.context.view_layer.objects.active = ob
    ob.select_set(True)
    assert bpy.ops.tessera.tessellate(use_object_settings=True) == {"FINISHED"}
    new = bpy.context.active_object
    bridge = addon_module("addon.bridge")
    arrays, _ = bridge.read_mesh(new.data)
    normals = arrays.corner_normals
    cpu = offscreen.render_triangles(arrays.positions, arrays.triangles, vp, size=(200, 200), normals=normals)
    assert (cpu[..., 0] > 0).sum() > 3000
    close = np.all(np.abs(cpu.astype(int) - gpu_img.astype(int)) <= 2, axis=-1)
    assert close.mean() >= 0.995, close.mean()
    assert entry.draw.triangle_count == len(arrays.triangles)
    # a new view re-selects; an edit of the mesh drops the upload
    far = _view(Camera, (12.0, -9.0, 6.0))
    before = entry.draw.triangle_count
    assert preview.update_levels(ob, entry, far.view, far.projection, 200, 200)
    assert entry.draw.triangle_count < before
    ob.data.vertices[0].co.x += 0.1
    ob.data.update()
    bpy.context.view_layer.update()
    assert ob not in preview.PREVIEW.cache
    assert preview.entry_for(ob) is not None


def test_operator_compute_path_equals_cpu(gpu_renderer, addon_module, clean_scene, bpy_module):
    bpy = bpy_module
    bridge = addon_module("addon.bridge")
    results = {}
    for device in ("CPU", "GPU"):
        _monkey(bpy)
        assert bpy.ops.tessera.tessellate(method="PHONG", level=5, evaluate_on=device) == {"FINISHED"}
        results[device], _ = bridge.read_mesh(bpy.context.active_object.data)
    cpu, gpu = results["CPU"], results["GPU"]
    assert np.array_equal(cpu.triangles, gpu.triangles)
    assert np.abs(cpu.positions - gpu.positions).max() <= 1e-5 * np.abs(cpu.positions).max()
    stored = compat().CUSTOM_NORMAL_STORAGE_ERROR  # both were stored: each within this of what was written
    assert np.abs(cpu.corner_normals - gpu.corner_normals).max() <= 1e-4 + 2 * stored


def test_tangent_space_map_in_the_preview_matches_the_node_group(gpu_renderer, addon_module, clean_scene,
                                                                   bpy_module):
    """A tangent-space vector map on a wavy grid: the preview (MikkTSpace corner tangents in the control data,
    the frame built in the vertex shader) draws the surface the geometry-nodes group displaces, pixel for pixel
    (linear method, level 1: the preview's vertices are the mesh's), shaded with the displaced surface's normals
    as Blender shades the displaced mesh."""
    bpy = bpy_module
    preview = addon_module("addon.tessellation.preview")
    offscreen = addon_module("gpu_shaders.offscreen")
    bridge = addon_module("addon.bridge")
    if not compat().has_uv_tangent_node():  # before 5.0: refused, with what is needed
        refuses_tangent_space(bpy)
        return
    Camera = addon_module("kernels.common.camera").Camera
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=24, y_subdivisions=24, size=2, rotation=(0.4, 0.2, 0.0))
    ob = bpy.context.active_object
    for v in ob.data.vertices:
        v.co.z = 0.3 * np.sin(2.5 * v.co.x) * np.cos(2.0 * v.co.y)
    for poly in ob.data.polygons:
        poly.use_smooth = True
    ob.data.update()
    size = 64
    assert bpy.ops.tessera.displacement_add(width=size, height=size, mode="VECTOR", space="TANGENT") == {"FINISHED"}
    v, u = (np.mgrid[0:size, 0:size] + 0.5) / size
    rgba = np.ones((size, size, 4), np.float32)
    rgba[..., 0] = 0.5 + 0.5 * np.sin(5 * u) * np.cos(4 * v)
    rgba[..., 1] = 0.5 + 0.5 * np.cos(3 * u + 1)
    rgba[..., 2] = 0.5 + 0.4 * np.sin(4 * v)
    d = ob.tessera.displacement
    d.image.pixels.foreach_set(rgba.ravel())
    d.image.update()
    d.mid_level, d.strength = 0.5, 0.3
    s = ob.tessera.tessellate
    s.method, s.level_mode, s.level, s.preview = "LINEAR", "UNIFORM", 1, True
    cam = Camera.looking_at((3.0, -3.5, 2.5), (0.0, 0.0, 0.0), fov_deg=45, width=200, height=200, far=100)
    entry = preview.entry_for(ob)
    preview.update_levels(ob, entry, cam.view, cam.projection, 200, 200)
    vp = cam.projection @ cam.view @ np.array(ob.matrix_world)
    disp = preview.displacement_for(ob)
    assert disp.mode == "TANGENT"
    white = {"color": (1.0, 1.0, 1.0, 1.0), "lit": False}
    gpu_flat = offscreen.render(lambda: entry.draw.draw(vp, displacement=disp, **white), size=(200, 200))
    gpu_img = offscreen.render(lambda: entry.draw.draw(vp, displacement=disp), size=(200, 200))
    plain = offscreen.render(lambda: entry.draw.draw(vp), size=(200, 200))
    rest, _ = bridge.read_mesh(ob.data)
    dg = bpy.context.evaluated_depsgraph_get()
    moved, _ = bridge.read_mesh(ob.evaluated_get(dg).to_mesh())
    ob.evaluated_get(dg).to_mesh_clear()
    assert np.abs(moved.positions - rest.positions).max() > 0.05
    cpu_flat = offscreen.render_triangles(moved.positions, moved.triangles, vp, size=(200, 200), **white)
    close = np.all(np.abs(cpu_flat.astype(int) - gpu_flat.astype(int)) <= 2, axis=-1)
    assert close.mean() >= 0.995, close.mean()  # the same surface, pixel for pixel
    assert np.mean(np.any(plain != gpu_img, axis=-1)) > 0.02

    # Shading: the displaced mesh's own normals (Blender's), not the undisplaced surface's.
    covered = cpu_flat[..., 0] > 127
    displaced = offscreen.render_triangles(moved.positions, moved.triangles, vp, size=(200, 200),
                                           normals=moved.corner_normals)
    undisplaced = offscreen.render_triangles(moved.positions, moved.triangles, vp, size=(200, 200),
                                             normals=rest.corner_normals)

    def error(reference):
        return float(np.abs(reference[covered, :3].astype(int) - gpu_img[covered, :3].astype(int)).mean())

    assert covered.sum() > 5000
    assert error(displaced) < 0.5 * error(undisplaced), (error(displaced), error(undisplaced))
    assert error(displaced) < 6.0, error(displaced)

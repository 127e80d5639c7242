"""PN / Phong / adaptive tessellation through Blender: Suzanne, cameras, stored settings (tier: blender)."""

import numpy as np
import pytest
from mesh_checks import edge_use_counts

pytestmark = pytest.mark.blender


def suzanne(bpy, smooth=True, sharp_angle=None):
    bpy.ops.mesh.primitive_monkey_add(location=(0.5, -0.2, 0.1), rotation=(0.2, 0.0, 0.4))
    ob = bpy.context.active_object
    if smooth:
        bpy.ops.object.shade_smooth()
    if sharp_angle is not None:
        bpy.ops.object.shade_smooth_by_angle(angle=sharp_angle)
    return ob


def add_camera(bpy, scene, location=(4.0, -5.0, 3.0)):
    data = bpy.data.cameras.new("Cam")
    cam = bpy.data.objects.new("Cam", data)
    scene.collection.objects.link(cam)
    cam.location = location
    direction = -np.array(location, float)
    import mathutils
    cam.rotation_euler = mathutils.Vector(direction).to_track_quat("-Z", "Y").to_euler()
    scene.camera = cam
    scene.render.resolution_x, scene.render.resolution_y = 640, 480
    return cam


def mesh_arrays(addon_module, ob):
    bridge = addon_module("addon.bridge")
    arrays, _ = bridge.read_mesh(ob.data)
    return arrays


@pytest.mark.parametrize("method", ["PN", "PHONG"])
def test_curved_methods_on_suzanne_store_their_settings(clean_scene, bpy_module, method):
    bpy = bpy_module
    ob = suzanne(bpy)
    assert bpy.ops.tessera.tessellate(method=method, level=4) == {"FINISHED"}
    new = bpy.context.active_object
    assert new is not ob and len(new.data.polygons) == 968 * 24
    stored = new.tessera.tessellate
    assert stored.stored and stored.method == method and stored.level == 4
    assert ob.tessera.tessellate.method == method
    normals = np.array([n.vector for n in new.data.corner_normals])
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-5)
    first = np.array([v.co for v in new.data.vertices])
    # A batch script re-runs the stored settings on the source object and gets the same mesh.
    bpy.context.view_layer.objects.active = ob
    assert bpy.ops.tessera.tessellate(use_object_settings=True) == {"FINISHED"}
    again = np.array([v.co for v in bpy.context.active_object.data.vertices])
    assert np.array_equal(first, again)


def test_sharp_suzanne_stays_closed_where_the_input_is(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    ob = suzanne(bpy, sharp_angle=np.radians(40))
    tess = addon_module("kernels.tessellation.tessellate")
    adaptive = addon_module("kernels.tessellation.adaptive")
    camera_mod = addon_module("kernels.common.camera")
    topology = addon_module("kernels.common.topology")
    arrays = mesh_arrays(addon_module, ob)
    edges, face_edges, _ = topology.triangle_edges(arrays.triangles)
    _, input_uses = edge_use_counts(arrays.triangles)
    rng = np.random.default_rng(5)
    for _ in range(8):
        direction = rng.normal(size=3)
        eye = direction / np.linalg.norm(direction) * rng.uniform(2, 9)
        camera = camera_mod.Camera.looking_at(eye, (0, 0, 0), fov_deg=rng.uniform(25, 70), width=960, height=540)
        settings = adaptive.AdaptiveSettings(metrics=("PROJECTED", "SILHOUETTE", "CURVATURE"), max_level=10,
                                             edge_pixels=15)
        edge, inner = adaptive.adaptive_levels(arrays.positions, arrays.triangles, settings, camera,
                                               arrays.corner_normals)
        sides = adaptive.face_side_edge_levels(arrays.positions, arrays.triangles, settings, camera,
                                               arrays.corner_normals)
        assert np.array_equal(sides, edge[face_edges])
        out = tess.tessellate(arrays, edge, inner, method="PN").mesh
        _, uses = edge_use_counts(out.triangles)
        assert uses.max() <= 2
        # Only the input's own open borders stay open, each split into its segment count.
        segments = np.ceil(edge[input_uses == 1]).sum()
        assert (uses == 1).sum() == segments


def test_adaptive_for_the_scene_camera(clean_scene, bpy_module):
    bpy = bpy_module
    ob = suzanne(bpy)
    add_camera(bpy, clean_scene)
    assert bpy.ops.tessera.tessellate(method="PN", level_mode="ADAPTIVE", metrics={"PROJECTED", "SILHOUETTE"},
                                      max_level=12, edge_pixels=8) == {"FINISHED"}
    near = len(bpy.context.active_object.data.polygons)
    assert near > 968
    clean_scene.camera.location = (40.0, -50.0, 30.0)  # ten times farther: fewer triangles
    bpy.context.view_layer.objects.active = ob
    assert bpy.ops.tessera.tessellate(use_object_settings=True) == {"FINISHED"}
    far = len(bpy.context.active_object.data.polygons)
    assert 968 <= far < near


def test_adaptive_without_a_camera_fails_cleanly(clean_scene, bpy_module):
    bpy = bpy_module
    suzanne(bpy)
    clean_scene.camera = None
    objects = len(bpy.data.objects)
    with pytest.raises(RuntimeError, match="camera"):
        bpy.ops.tessera.tessellate(level_mode="ADAPTIVE", metrics={"PROJECTED"})
    with pytest.raises(RuntimeError, match="viewport"):
        bpy.ops.tessera.tessellate(level_mode="ADAPTIVE", metrics={"DISTANCE"}, camera_source="VIEWPORT")
    assert len(bpy.data.objects) == objects
    assert bpy.ops.tessera.tessellate(level_mode="ADAPTIVE", metrics={"CURVATURE"}) == {"FINISHED"}


def test_split_mode_reports_the_opened_edges(clean_scene, bpy_module):
    bpy = bpy_module
    suzanne(bpy, smooth=False)  # flat shaded: every edge is sharp
    assert bpy.ops.tessera.tessellate(method="PHONG", normal_mode="SPLIT", level=2) == {"FINISHED"}
    me = bpy.context.active_object.data
    _, uses = edge_use_counts(np.array([p.vertices[:] for p in me.polygons]))
    assert (uses == 1).sum() > 0


def test_sidebar_panel_is_registered(addon, bpy_module):
    assert hasattr(bpy_module.types, "TESSERA_PT_tessellation")
    assert hasattr(bpy_module.types.Object, "tessera")

"""``tessera.terrain_add`` and ``tessera.terrain_bake`` on real scenes (tier: blender)."""

import numpy as np
import pytest

pytestmark = pytest.mark.blender


def write_height_png(path, size=129):
    import OpenImageIO as oiio

    y, x = np.mgrid[0:size, 0:size] / size
    h = 0.5 + 0.3 * np.sin(6 * x) * np.cos(4 * y)
    h[:, : size // 4] = 0.1
    data = np.round(h * 65535).astype(np.uint16)
    out = oiio.ImageOutput.create(path)
    out.open(path, oiio.ImageSpec(size, size, 1, "uint16"))
    out.write_image(np.ascontiguousarray(data[::-1])[..., None])
    out.close()
    return data


def mesh_tris(me):
    pos = np.empty(len(me.vertices) * 3, np.float32)
    me.attributes["position"].data.foreach_get("vector", pos)
    verts = np.empty(len(me.loops), np.int32)
    me.attributes[".corner_vert"].data.foreach_get("value", verts)
    return pos.reshape(-1, 3), verts.reshape(-1, 3)


def boundary_edge_count(tris):
    e = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    _, c = np.unique(e, axis=0, return_counts=True)
    return int((c == 1).sum()), int(c.max())


def add_camera(bpy, location, target=(0, 0, 0)):
    import mathutils

    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    bpy.context.scene.collection.objects.link(cam)
    cam.location = location
    cam.rotation_euler = (mathutils.Vector(target) - cam.location).to_track_quat("-Z", "Y").to_euler()
    bpy.context.scene.camera = cam
    bpy.context.scene.render.resolution_x, bpy.context.scene.render.resolution_y = 640, 360
    bpy.context.view_layer.update()
    return cam


def test_terrain_add_and_bake_for_the_camera(clean_scene, bpy_module, tmp_path):
    bpy = bpy_module
    path = str(tmp_path / "h.png")
    data = write_height_png(path)
    add_camera(bpy, (0, -150, 60))
    assert bpy.ops.tessera.terrain_add(filepath=path, texel_size=1.0, height_scale=40.0, tile_size=32,
                                       culling=False) == {"FINISHED"}
    ob = bpy.context.active_object
    s = ob.tessera.terrain
    assert s.is_terrain and s.filepath == path and s.tile_size == 32
    pos, tris = mesh_tris(ob.data)
    assert 0 < len(tris) < 2 * 128 * 128
    n_boundary, most = boundary_edge_count(tris)
    assert most == 2
    full_border = 4 * 128
    assert n_boundary <= full_border  # only the outer border (edges there are at most one per texel)
    # heights: every vertex lies on the map (16-bit kept: heights are multiples of 40/65535)
    lo, hi = 40.0 * float(data.min()) / 65535, 40.0 * float(data.max()) / 65535  # floats: no uint16 overflow
    assert pos[:, 2].min() >= lo - 1e-4 and pos[:, 2].max() <= hi + 1e-4
    assert "UVMap" in ob.data.uv_layers
    before = len(tris)
    bpy.context.scene.camera.location = (0, -2000, 400)  # far away: fewer triangles
    bpy.context.view_layer.update()
    assert bpy.ops.tessera.terrain_bake() == {"FINISHED"}
    assert len(mesh_tris(ob.data)[1]) < before
    assert len(bpy.data.meshes) == 1  # the old mesh was replaced, not leaked
    assert not ob.data.validate(verbose=False)


def test_terrain_add_refuses_bad_input_and_leaves_the_scene_unchanged(clean_scene, bpy_module, tmp_path):
    bpy = bpy_module
    raw = tmp_path / "h.r16"
    np.zeros((10, 10), "<u2").tofile(raw)
    n_objects, n_meshes = len(bpy.data.objects), len(bpy.data.meshes)
    with pytest.raises(RuntimeError, match="bytes"):
        bpy.ops.tessera.terrain_add(filepath=str(raw), raw_width=12, raw_height=10)
    with pytest.raises(RuntimeError, match="No such"):
        bpy.ops.tessera.terrain_add(filepath=str(tmp_path / "nothing.png"))
    assert len(bpy.data.objects) == n_objects and len(bpy.data.meshes) == n_meshes
    assert bpy.ops.tessera.terrain_add(filepath=str(raw), raw_width=10, raw_height=10) == {"FINISHED"}
    assert len(bpy.context.active_object.data.polygons) == 2  # flat: one tile, one quad, two triangles


def test_terrain_from_a_blender_image_without_camera_uses_t_max(clean_scene, bpy_module):
    bpy = bpy_module
    img = bpy.data.images.new("hm", 65, 65, float_buffer=True)
    px = np.zeros((65, 65, 4), np.float32)
    px[..., 0] = np.linspace(0, 1, 65)[None, :] ** 2
    img.pixels.foreach_set(px.ravel())
    bpy.context.scene.camera = None
    assert bpy.ops.tessera.terrain_add(source="IMAGE", image_name="hm", tile_size=16, height_scale=10.0) \
        == {"FINISHED"}
    ob = bpy.context.active_object
    pos, tris = mesh_tris(ob.data)
    assert len(tris) > 2 * 16  # curved: refined by T_max without a camera
    assert np.isclose(pos[:, 2].max(), 10.0, atol=1e-5)
    with pytest.raises(RuntimeError, match="camera"):
        bpy.ops.tessera.terrain_bake()  # the bake needs a camera

"""Mesh <-> numpy round trips through the bridge (tier: blender)."""

import numpy as np
import pytest
from blender_helpers import compat

pytestmark = pytest.mark.blender


@pytest.fixture
def bridge(addon_module):
    return addon_module("addon.bridge")


def test_round_trip_keeps_everything(clean_scene, bpy_module, bridge):
    bpy = bpy_module
    bpy.ops.mesh.primitive_uv_sphere_add(segments=12, ring_count=6)  # quads and triangle fans
    me = bpy.context.active_object.data
    col = me.color_attributes.new("Paint", "FLOAT_COLOR", "CORNER")
    rng = np.random.default_rng(0)
    col.data.foreach_set("color", rng.random(len(me.loops) * 4).astype(np.float32))
    pt = me.attributes.new("weight", "FLOAT", "POINT")
    pt.data.foreach_set("value", rng.random(len(me.vertices)).astype(np.float32))
    mi = me.attributes.new("material_index", "INT", "FACE")
    mi.data.foreach_set("value", (np.arange(len(me.polygons)) % 2).astype(np.int32))
    me.attributes.new("ints_on_points", "INT", "POINT")

    arrays, info = bridge.read_mesh(me)
    assert arrays.triangles.shape == (len(me.loop_triangles), 3)
    assert "ints_on_points (POINT INT)" in info.skipped
    out = bridge.write_mesh("RoundTrip", arrays, info)
    again, _ = bridge.read_mesh(out)
    assert np.array_equal(again.positions, arrays.positions)
    assert np.array_equal(again.triangles, arrays.triangles)
    for name in ("UVMap", "Paint"):
        assert np.allclose(again.corner_attributes[name], arrays.corner_attributes[name])
    assert np.array_equal(again.point_attributes["weight"], arrays.point_attributes["weight"])
    assert np.array_equal(again.face_attributes["material_index"], arrays.face_attributes["material_index"])
    stored = compat().CUSTOM_NORMAL_STORAGE_ERROR  # what this Blender's custom-normal storage keeps
    assert np.allclose(again.corner_normals, arrays.corner_normals, atol=1e-4 + stored)
    assert out.uv_layers.active.name == "UVMap" and out.attributes["UVMap"].data_type == "FLOAT2"


def test_failed_write_leaves_no_mesh(clean_scene, bpy_module, bridge, addon_module):
    bpy = bpy_module
    arrays_cls = addon_module("kernels.common.mesh_arrays").MeshArrays
    bad = arrays_cls(
        positions=np.zeros((3, 3), np.float32),
        triangles=np.array([[0, 1, 2]], np.int32),
        face_attributes={"flag": np.zeros(1)},
        attribute_types={"flag": "NOT_A_TYPE"},
    )
    before = len(bpy.data.meshes)
    with pytest.raises(KeyError):
        bridge.write_mesh("Broken", bad)
    assert len(bpy.data.meshes) == before

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


@pytest.mark.parametrize("sizes", ["triangles", "mixed"])
def test_face_offsets_written_in_one_copy_equal_foreach_set(clean_scene, bpy_module, addon_module, sizes):
    """`compat.set_face_offsets` takes the bulk copy on every supported Blender, and the mesh it leaves has the same
    face starts and sizes as the per-face setter's, and validates clean."""
    bpy = bpy_module
    compat = addon_module("addon.compat")
    rng = np.random.default_rng(7)
    n_faces = 20000
    size = np.full(n_faces, 3) if sizes == "triangles" else rng.integers(3, 9, n_faces)
    starts = np.r_[0, np.cumsum(size)[:-1]].astype(np.int32)
    n_verts = 5000
    corner_verts = np.concatenate([rng.choice(n_verts, k, replace=False) for k in size]).astype(np.int32)
    positions = rng.normal(size=(n_verts, 3)).astype(np.float32)
    got = {}
    for bulk in (True, False):
        me = bpy.data.meshes.new(f"offsets_{bulk}")
        me.vertices.add(n_verts)
        me.loops.add(len(corner_verts))
        me.polygons.add(n_faces)
        me.attributes["position"].data.foreach_set("vector", positions.ravel())
        me.attributes[".corner_vert"].data.foreach_set("value", corner_verts)
        if bulk:
            assert compat.set_face_offsets(me, starts)
        else:
            me.polygons.foreach_set("loop_start", starts)
        me.update(calc_edges=True)
        ls, lt = np.empty(n_faces, np.int32), np.empty(n_faces, np.int32)
        me.polygons.foreach_get("loop_start", ls)
        me.polygons.foreach_get("loop_total", lt)
        cv = np.empty(len(me.loops), np.int32)
        me.attributes[".corner_vert"].data.foreach_get("value", cv)
        got[bulk] = (ls, lt, cv, len(me.edges))
        assert not me.validate(verbose=False)  # nothing to repair
    assert np.array_equal(got[True][0], starts) and np.array_equal(got[True][1], size)
    for a, b in zip(got[True], got[False], strict=True):
        assert np.array_equal(a, b)


def test_face_offsets_fall_back_below_the_bulk_size(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    compat = addon_module("addon.compat")
    me = bpy.data.meshes.new("few")
    me.vertices.add(4)
    me.loops.add(6)
    me.polygons.add(2)
    me.attributes[".corner_vert"].data.foreach_set("value", np.array([0, 1, 2, 0, 2, 3], np.int32))
    assert not compat.set_face_offsets(me, np.array([0, 3], np.int32))
    me.update(calc_edges=True)
    assert [tuple(p.vertices) for p in me.polygons] == [(0, 1, 2), (0, 2, 3)]
    with pytest.raises(ValueError):
        compat.set_face_offsets(me, np.array([0], np.int32))

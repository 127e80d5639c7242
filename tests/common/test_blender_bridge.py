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
    """`mesh_memory.set_face_offsets` takes the bulk copy on every supported Blender, and the mesh it leaves has the
    same face starts and sizes as the per-face setter's, and validates clean."""
    bpy = bpy_module
    memory = addon_module("addon.mesh_memory")
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
            assert memory.set_face_offsets(me, starts)
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
    memory = addon_module("addon.mesh_memory")
    me = bpy.data.meshes.new("few")
    me.vertices.add(4)
    me.loops.add(6)
    me.polygons.add(2)
    me.attributes[".corner_vert"].data.foreach_set("value", np.array([0, 1, 2, 0, 2, 3], np.int32))
    assert not memory.set_face_offsets(me, np.array([0, 3], np.int32))
    me.update(calc_edges=True)
    assert [tuple(p.vertices) for p in me.polygons] == [(0, 1, 2), (0, 2, 3)]
    with pytest.raises(ValueError):
        memory.set_face_offsets(me, np.array([0], np.int32))



@pytest.mark.parametrize(("data_type", "domain", "prop", "bulk"), [
    ("FLOAT_VECTOR", "POINT", "vector", True), ("FLOAT2", "CORNER", "vector", True),
    ("FLOAT_COLOR", "CORNER", "color", True), ("FLOAT", "FACE", "value", True), ("INT", "FACE", "value", True),
    ("BOOLEAN", "FACE", "value", True), ("INT8", "POINT", "value", False), ("BYTE_COLOR", "POINT", "color", False)])
def test_bulk_writes_equal_foreach_set(clean_scene, bpy_module, addon_module, data_type, domain, prop, bulk):
    """`mesh_memory.write_items` copies straight into the attribute's memory where its items are one array of the
    values' type (and leaves the same values as ``foreach_set``, read back both ways); types Blender stores
    otherwise (8-bit integers and colours) go through ``foreach_set``."""
    bpy = bpy_module
    memory = addon_module("addon.mesh_memory")
    n_faces = 20_000
    width = {"FLOAT_VECTOR": 3, "FLOAT2": 2, "FLOAT_COLOR": 4, "BYTE_COLOR": 4}.get(data_type, 1)
    got = []
    for use_bulk in (True, False):
        me = bpy.data.meshes.new("bulk")
        me.vertices.add(3 * n_faces)
        me.loops.add(3 * n_faces)
        me.polygons.add(n_faces)
        me.attributes[".corner_vert"].data.foreach_set("value", np.arange(3 * n_faces, dtype=np.int32))
        memory.set_face_offsets(me, np.arange(0, 3 * n_faces, 3, dtype=np.int32))
        attr = me.attributes.new("probe", data_type, domain)
        n = len(attr.data)
        rng = np.random.default_rng(3)  # the same values both ways
        values = {"INT": rng.integers(-1000, 1000, n).astype(np.int32), "BOOLEAN": rng.random(n) < 0.5,
                  "INT8": rng.integers(-100, 100, n).astype(np.int32)}.get(
                      data_type, rng.random((n, width)).astype(np.float32).reshape(n, -1))
        if use_bulk:
            assert memory.write_items(attr.data, prop, values, min_bytes=0) == bulk
        else:
            attr.data.foreach_set(prop, values.ravel())
        out = np.empty(values.size, values.dtype)
        me.attributes["probe"].data.foreach_get(prop, out)
        got.append(out)
        bpy.data.meshes.remove(me)
    assert np.array_equal(got[0], got[1])


def test_bulk_written_mesh_equals_the_foreach_set_mesh(clean_scene, bpy_module, addon_module, monkeypatch):
    """A tessellation written by the bridge (bulk copies) and the same arrays written with ``foreach_set`` give equal
    meshes after ``update``: positions, corners, faces, edges, UVs, normals Blender derives, bounds."""
    bpy = bpy_module
    bridge = addon_module("addon.bridge")
    tess = addon_module("kernels.tessellation.tessellate")
    bpy.ops.mesh.primitive_monkey_add()
    bpy.ops.mesh.uv_texture_add()
    arrays, info = bridge.read_mesh(bpy.context.active_object.data)
    result = tess.tessellate(arrays, tess.uniform_levels(arrays, 12), method="PN")
    edges = result.refinement.output_edges()
    bulk = bridge.write_mesh("bulk", result.mesh, info, edges=edges)
    monkeypatch.setattr(bridge, "write_items",
                        lambda c, prop, v, min_bytes=0: c.foreach_set(prop, np.ascontiguousarray(v).ravel()))
    monkeypatch.setattr(bridge, "set_face_offsets", lambda me, s: me.polygons.foreach_set("loop_start", s))
    plain = bridge.write_mesh("plain", result.mesh, info, edges=edges)

    def arrays_of(me):
        assert not me.validate(verbose=False)
        out = {}
        for name, collection, prop, dtype, width in (
                ("co", me.vertices, "co", np.float32, 3), ("normal", me.vertices, "normal", np.float32, 3),
                ("loop_start", me.polygons, "loop_start", np.int32, 1),
                ("corner", me.loops, "vertex_index", np.int32, 1), ("edge", me.edges, "vertices", np.int32, 2),
                ("corner_edge", me.loops, "edge_index", np.int32, 1),
                ("uv", me.uv_layers.active.data, "uv", np.float32, 2),
                ("corner_normal", me.corner_normals, "vector", np.float32, 3)):
            a = np.empty(len(collection) * width, dtype)
            collection.foreach_get(prop, a)
            out[name] = a
        return out

    a, b = arrays_of(bulk), arrays_of(plain)
    assert len(a["co"]) > 30000 * 3
    for key in a:
        assert np.array_equal(a[key], b[key]), key
    ob_a, ob_b = bpy.data.objects.new("a", bulk), bpy.data.objects.new("b", plain)
    assert [tuple(c) for c in ob_a.bound_box] == [tuple(c) for c in ob_b.bound_box]


def test_bulk_writes_of_nothing_and_of_the_wrong_size(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    memory = addon_module("addon.mesh_memory")
    me = bpy.data.meshes.new("empty")
    me.vertices.add(4)
    faces = me.attributes.new("per_face", "FLOAT", "FACE")  # no faces: nothing to write, and no error
    assert memory.write_items(faces.data, "value", np.zeros(0, np.float32)) is False
    with pytest.raises(ValueError):
        memory.write_items(me.attributes["position"].data, "vector", np.zeros((5, 3), np.float32))
    with pytest.raises(ValueError):
        memory.write_items(me.attributes["position"].data, "vector", np.zeros((0, 3), np.float32))

"""The add-on as Blender loads it: registration, the tessellate operator, failure safety (tier: blender)."""

import numpy as np
import pytest
from blender_helpers import compat

pytestmark = pytest.mark.blender


def add_suzanne(bpy):
    bpy.ops.mesh.primitive_monkey_add(location=(1.0, 2.0, 3.0), rotation=(0.3, 0.0, 0.5))
    ob = bpy.context.active_object
    mat = bpy.data.materials.new("TessMat")
    ob.data.materials.append(mat)
    return ob


def snapshot(bpy):
    return (
        sorted(o.name for o in bpy.data.objects),
        sorted(m.name for m in bpy.data.meshes),
        {o.name: (o.data.name, len(o.data.vertices)) for o in bpy.data.objects if o.type == "MESH"},
    )


def test_registered(addon, bpy_module):
    assert hasattr(bpy_module.types, "TESSERA_OT_tessellate")
    assert bpy_module.ops.tessera.tessellate.idname() == "TESSERA_OT_tessellate"


def test_poll_explains_itself(clean_scene, bpy_module):
    bpy = bpy_module
    bpy.context.view_layer.objects.active = None
    assert not bpy.ops.tessera.tessellate.poll()
    with pytest.raises(RuntimeError, match="Select a mesh object"):
        bpy.ops.tessera.tessellate()


def test_new_object_has_the_hardware_triangle_count(clean_scene, bpy_module):
    bpy = bpy_module
    ob = add_suzanne(bpy)
    ob.data.calc_loop_triangles()
    n_tris = len(ob.data.loop_triangles)
    assert bpy.ops.tessera.tessellate(level=4) == {"FINISHED"}
    new = bpy.context.active_object
    assert new is not ob and new.name.startswith(ob.name)
    assert len(new.data.polygons) == 24 * n_tris
    assert np.allclose(np.array(new.matrix_world), np.array(ob.matrix_world))
    assert new.data.materials[0].name == "TessMat"
    assert "UVMap" in new.data.uv_layers and new.data.has_custom_normals
    assert ob.data.vertices and len(ob.data.polygons) == 500  # the source is untouched


@pytest.mark.parametrize("hide_source, output, hidden", [
    (True, "NEW_OBJECT", True), (False, "NEW_OBJECT", False), (True, "REPLACE", False)])
def test_the_source_is_hidden_under_a_new_object_unless_asked_not_to(clean_scene, bpy_module, hide_source, output,
                                                                     hidden):
    bpy = bpy_module
    ob = add_suzanne(bpy)
    assert bpy.ops.tessera.tessellate(level=2, output=output, hide_source=hide_source) == {"FINISHED"}
    new = bpy.context.active_object
    assert ob.hide_get() is hidden and ob.hide_render is hidden
    assert not new.hide_get() and not new.hide_render and new.select_get()


def test_a_failed_run_on_several_objects_leaves_every_source_shown(clean_scene, bpy_module):
    bpy = bpy_module
    me = bpy.data.meshes.new("Points")  # a mesh without faces: its run fails after the active object's succeeded
    me.from_pydata([(0, 0, 0), (1, 0, 0)], [(0, 1)], [])
    wire = bpy.data.objects.new("Wire", me)
    clean_scene.collection.objects.link(wire)
    ob = add_suzanne(bpy)  # active, so it runs first
    wire.select_set(True)
    names = sorted(o.name for o in bpy.data.objects)
    with pytest.raises(RuntimeError, match="no faces"):
        bpy.ops.tessera.tessellate(level=2)
    assert sorted(o.name for o in bpy.data.objects) == names
    assert not ob.hide_get() and not wire.hide_get() and not ob.hide_render


def test_linear_tessellation_keeps_shape_and_shading(clean_scene, bpy_module):
    bpy = bpy_module
    ob = add_suzanne(bpy)
    bpy.ops.object.shade_smooth()
    bpy.ops.tessera.tessellate(method="LINEAR", level=3)
    new = bpy.context.active_object
    src, dst = ob.data, new.data
    src_pos = np.array([v.co for v in src.vertices])
    dst_pos = np.array([v.co for v in dst.vertices])
    assert np.array_equal(dst_pos[: len(src_pos)].astype(np.float32), src_pos.astype(np.float32))
    lo, hi = src_pos.min(0), src_pos.max(0)
    assert np.all(dst_pos.min(0) >= lo - 1e-6) and np.all(dst_pos.max(0) <= hi + 1e-6)
    # the corner normals at the original vertices are the source's smooth normals
    normals = np.zeros((len(dst.loops), 3), np.float32)
    dst.corner_normals.foreach_get("vector", normals.ravel())
    verts = np.zeros(len(dst.loops), np.int32)
    dst.loops.foreach_get("vertex_index", verts)
    src_vn = np.zeros((len(src.vertices), 3), np.float32)
    src.vertex_normals.foreach_get("vector", src_vn.ravel())
    at_corner = verts < len(src.vertices)
    stored = compat().CUSTOM_NORMAL_STORAGE_ERROR  # what this Blender's custom-normal storage keeps
    assert np.allclose(normals[at_corner], src_vn[verts[at_corner]], atol=1e-4 + stored)


def test_replace_keeps_name_and_fractional_spacing(clean_scene, bpy_module):
    bpy = bpy_module
    ob = add_suzanne(bpy)
    name = ob.data.name
    assert bpy.ops.tessera.tessellate(level=2.5, spacing="FRACTIONAL_EVEN", output="REPLACE") == {"FINISHED"}
    assert bpy.context.active_object is ob and ob.data.name == name
    assert len(ob.data.polygons) == 968 * 24  # levels 2.5 -> 4 segments (even)
    assert ob.data.materials[0].name == "TessMat"


def test_failure_leaves_the_scene_unchanged(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    add_suzanne(bpy)
    prefs = addon_module("addon.preferences").get_preferences()
    before = snapshot(bpy)
    old_budget = prefs.memory_budget_mb
    prefs.memory_budget_mb = 1
    try:
        with pytest.raises(RuntimeError, match="over the memory budget"):
            bpy.ops.tessera.tessellate(level=30)
    finally:
        prefs.memory_budget_mb = old_budget
    assert snapshot(bpy) == before
    # a mesh without faces: refused, nothing created
    me = bpy.data.meshes.new("Points")
    me.from_pydata([(0, 0, 0), (1, 0, 0)], [(0, 1)], [])
    wire = bpy.data.objects.new("Wire", me)
    clean_scene.collection.objects.link(wire)
    bpy.context.view_layer.objects.active = wire
    before = snapshot(bpy)
    with pytest.raises(RuntimeError, match="no faces"):
        bpy.ops.tessera.tessellate(output="REPLACE")
    assert snapshot(bpy) == before


def test_exported_obj_has_the_tessellated_faces(clean_scene, bpy_module, tmp_path):
    bpy = bpy_module
    add_suzanne(bpy)
    bpy.ops.tessera.tessellate(level=2)
    new = bpy.context.active_object
    n = len(new.data.polygons)
    path = tmp_path / "t.obj"
    assert bpy.ops.wm.obj_export(filepath=str(path), export_selected_objects=True) == {"FINISHED"}
    faces = sum(1 for line in path.read_text().splitlines() if line.startswith("f "))
    assert faces == n


@pytest.mark.parametrize("levels", [{"level": 1}, {"level": 5},
                                    {"level_mode": "ADAPTIVE", "metrics": {"CURVATURE"}, "spacing": "FRACTIONAL_EVEN",
                                     "max_level": 12.0}])
def test_written_edges_are_the_ones_blender_computes(clean_scene, bpy_module, levels):
    """The operator hands Blender the refinement's own edges (no edge computation), uniform (per pattern class)
    and adaptive (per face): the mesh validates clean and its edges and corner edges are those Blender derives
    from the faces alone."""
    bpy = bpy_module
    add_suzanne(bpy)
    assert bpy.ops.tessera.tessellate(method="PN", **levels) == {"FINISHED"}
    me = bpy.context.active_object.data
    assert not me.validate(verbose=False)  # nothing to correct

    def edge_data(mesh):
        ev = np.empty(2 * len(mesh.edges), np.int32)
        mesh.attributes[".edge_verts"].data.foreach_get("value", ev)
        ce = np.empty(len(mesh.loops), np.int32)
        mesh.attributes[".corner_edge"].data.foreach_get("value", ce)
        ev = np.sort(ev.reshape(-1, 2), axis=1)
        return {tuple(e) for e in ev}, [tuple(ev[i]) for i in ce]

    ours = edge_data(me)
    rebuilt = me.copy()
    rebuilt.edges.foreach_set("vertices", np.zeros(2 * len(rebuilt.edges), np.int32))  # forget them
    rebuilt.update(calc_edges=True)
    rebuilt.validate(verbose=False)
    theirs = edge_data(rebuilt)
    bpy.data.meshes.remove(rebuilt)
    assert ours[0] == theirs[0] and ours[1] == theirs[1]
    assert len(ours[0]) == len(me.edges)

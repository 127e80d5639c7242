"""``tessera.loop_subdivide`` on Blender meshes (tier: blender): the kernel's result written as it is, creases
from Blender's marks, UVs carried, open meshes, bad input refused with nothing changed."""

import os

import numpy as np
import pytest
from blender_helpers import UiOperator, select_only

pytestmark = pytest.mark.blender


def arrays_of(me):
    n_v, n_c, n_e = len(me.vertices), len(me.loops), len(me.edges)
    pos = np.empty(n_v * 3, np.float32)
    me.attributes["position"].data.foreach_get("vector", pos)
    corners = np.empty(n_c, np.int32)
    me.attributes[".corner_vert"].data.foreach_get("value", corners)
    corner_edge = np.empty(n_c, np.int32)
    me.attributes[".corner_edge"].data.foreach_get("value", corner_edge)
    return pos.reshape(-1, 3), corners.reshape(-1, 3), np.bincount(corner_edge, minlength=n_e)


def delete_face(bpy, ob, index):
    """Delete face ``index`` of ``ob`` (active, Object Mode) the way a user would, in Edit Mode."""
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="DESELECT")
    bpy.ops.object.mode_set(mode="OBJECT")
    ob.data.polygons[index].select = True
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.delete(type="FACE")
    bpy.ops.object.mode_set(mode="OBJECT")


def kernel_of(addon_module, bpy, ob, levels, **kw):
    """The kernel's result on what the operator reads (the object's mesh, triangulated by Blender)."""
    bridge = addon_module("addon.bridge")
    loop = addon_module("kernels.subdivision.loop")
    rules = addon_module("kernels.subdivision.loop_rules")
    arrays, _ = bridge.read_mesh(ob.data)
    marks = bridge.read_edge_marks(ob.data)
    return loop.loop_subdivide(arrays.positions, arrays.triangles, levels,
                               creases=(marks.pairs, rules.crease_to_sharpness(marks.crease)),
                               corner_data=arrays.corner_attributes, **kw), marks


def test_suzanne_gives_the_kernels_mesh_with_uvs(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    bpy.ops.mesh.primitive_monkey_add()
    ob = bpy.context.active_object
    ob.data.materials.append(bpy.data.materials.new("Skin"))
    assert bpy.ops.tessera.loop_subdivide(levels=2) == {"FINISHED"}
    out = bpy.context.active_object
    assert out is not ob and out.name == "Suzanne.loop" and out.data.materials[0].name == "Skin"
    assert ob.hide_get() and ob.hide_render and not out.hide_render  # the new object shows, not the source under it
    ref, marks = kernel_of(addon_module, bpy, ob, 2)
    assert marks.n_gons == 468
    pos, tris, use = arrays_of(out.data)
    assert np.array_equal(pos, ref.positions) and np.array_equal(tris, ref.triangles)
    assert not out.data.validate(verbose=False)  # the kernel's edges need no fixing
    # Suzanne's eyes are open: every coarse boundary edge became 4 boundary edges, the rest is manifold
    _, _, coarse_use = arrays_of(ob.data)
    assert np.count_nonzero(use == 1) == 4 * np.count_nonzero(coarse_use == 1) and use.max() == 2
    uv = np.empty(len(out.data.loops) * 2, np.float32)
    out.data.uv_layers["UVMap"].data.foreach_get("uv", uv)
    assert np.array_equal(uv.reshape(-1, 3, 2), ref.corner_attributes["UVMap"])
    assert np.all(np.isfinite(pos))


def test_sharp_and_creased_edges_are_creases(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=2)
    ob = bpy.context.active_object
    me = ob.data
    sharp = me.attributes.new("sharp_edge", "BOOLEAN", "EDGE")
    flags = np.zeros(len(me.edges), bool)
    flags[::7] = True
    sharp.data.foreach_set("value", flags)
    crease = me.attributes.new("crease_edge", "FLOAT", "EDGE")
    values = np.zeros(len(me.edges), np.float32)
    values[3::11] = 0.5
    crease.data.foreach_set("value", values)
    assert bpy.ops.tessera.loop_subdivide(levels=2) == {"FINISHED"}
    out = bpy.context.active_object
    ref, marks = kernel_of(addon_module, bpy, ob, 2)
    assert len(marks.pairs) == np.count_nonzero(flags | (values > 0))
    pos, _, use = arrays_of(out.data)
    assert np.array_equal(pos, ref.positions) and np.all(use == 2)  # closed stays closed
    # the marks go on: 4 sharp halves per sharp edge, crease 0.5 (sharpness 2.5) is 0.5 / sqrt(10) after 2 levels
    out_sharp = np.empty(len(out.data.edges), bool)
    out.data.attributes["sharp_edge"].data.foreach_get("value", out_sharp)
    assert out_sharp.sum() == 4 * flags.sum()
    out_crease = np.empty(len(out.data.edges), np.float32)
    out.data.attributes["crease_edge"].data.foreach_get("value", out_crease)
    soft = (values > 0) & ~flags
    assert np.count_nonzero(out_crease) == 4 * soft.sum()
    assert np.allclose(out_crease[out_crease > 0], np.sqrt(0.5 / 10), rtol=1e-6)
    select_only(bpy, ob)
    assert bpy.ops.tessera.loop_subdivide(levels=2, use_creases=False) == {"FINISHED"}
    smooth, _, _ = arrays_of(bpy.context.active_object.data)
    assert not np.allclose(smooth, pos)


def test_open_grid_with_a_hole_and_replace(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=6, y_subdivisions=6)
    ob = bpy.context.active_object
    delete_face(bpy, ob, 14)
    ref, _ = kernel_of(addon_module, bpy, ob, 3, boundary="EDGE_AND_CORNER")
    coarse_arrays, _ = addon_module("addon.bridge").read_mesh(ob.data)
    coarse, coarse_tris = coarse_arrays.positions, coarse_arrays.triangles
    name = ob.data.name
    assert bpy.ops.tessera.loop_subdivide(levels=3, boundary="EDGE_AND_CORNER", output="REPLACE") == {"FINISHED"}
    assert bpy.context.active_object is ob and ob.data.name == name
    pos, _, use = arrays_of(ob.data)
    assert np.array_equal(pos, ref.positions) and np.all(np.isfinite(pos))
    single = np.flatnonzero(np.bincount(coarse_tris.ravel()) == 1)  # border vertices of a single triangle
    assert len(single) >= 2 and np.array_equal(pos[single], coarse[single])  # keep their place


def lit_scene(bpy, compat):
    """An icosphere between a red wall and a white floor under an area light."""
    red = bpy.data.materials.new("Red")
    red.diffuse_color = (0.9, 0.05, 0.05, 1.0)
    bpy.ops.mesh.primitive_plane_add(size=6, location=(-1.6, 0, 0), rotation=(0, 1.5708, 0))
    wall = bpy.context.active_object
    wall.data.materials.append(red)
    compat.use_material_nodes(red)
    red.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.9, 0.05, 0.05, 1.0)
    bpy.ops.mesh.primitive_plane_add(size=6, location=(0, 0, -1.2))
    bpy.ops.object.light_add(type="AREA", location=(0, 0, 3))
    bpy.context.active_object.data.energy = 200
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=1)
    return bpy.context.active_object


def test_baked_lighting_goes_to_every_level_without_seams(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    ob = lit_scene(bpy, addon_module("addon.compat"))
    engine = bpy.context.scene.render.engine
    n_objects, n_images = len(bpy.data.objects), len(bpy.data.images)
    assert bpy.ops.tessera.bake_lighting_hce(depth=2, samples=4, normals=2) == {"FINISHED"}
    assert bpy.context.scene.render.engine == engine and bpy.context.active_object is ob
    assert (len(bpy.data.objects), len(bpy.data.images)) == (n_objects, n_images)  # no temporary left
    hce = addon_module("kernels.subdivision.hce")
    arrays, _ = addon_module("addon.bridge").read_mesh(ob.data)
    packed = hce.unpack_container(ob.data["tessera_hce"], arrays.triangles)
    assert len(packed.node_start) == len(arrays.triangles) + 1
    for levels in (1, 3):
        select_only(bpy, ob)
        assert bpy.ops.tessera.loop_subdivide(levels=levels) == {"FINISHED"}
        out = bpy.context.active_object.data
        assert out.color_attributes.active_color.name == "BakedLight"
        col = np.empty(len(out.vertices) * 4, np.float32)
        out.color_attributes["BakedLight"].data.foreach_get("color", col)
        col = col.reshape(-1, 4)
        pos, _, _ = arrays_of(out)
        assert np.all(np.isfinite(col)) and np.all(col[:, :3] >= 0) and col[:, :3].max() > 0.05
        left = pos[:, 0] < -0.5  # facing the red wall: more red than green
        assert col[left, 0].mean() > col[left, 1].mean()


def test_stale_baked_lighting_is_reported_and_not_used(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    ob = lit_scene(bpy, addon_module("addon.compat"))
    assert bpy.ops.tessera.bake_lighting_hce(depth=1, samples=1) == {"FINISHED"}
    delete_face(bpy, ob, 0)
    assert bpy.ops.tessera.loop_subdivide(levels=1) == {"FINISHED"}
    assert "BakedLight" not in bpy.context.active_object.data.color_attributes


def test_baked_lighting_is_saved_with_the_file(clean_scene, bpy_module, addon_module, tmp_path):
    bpy = bpy_module
    ob = lit_scene(bpy, addon_module("addon.compat"))
    assert bpy.ops.tessera.bake_lighting_hce(depth=1, samples=2) == {"FINISHED"}
    blob, name = bytes(ob.data["tessera_hce"]), ob.name
    path = tmp_path / "baked.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    bpy.ops.wm.open_mainfile(filepath=str(path))
    ob = bpy.data.objects[name]
    assert bytes(ob.data["tessera_hce"]) == blob
    select_only(bpy, ob)
    assert bpy.ops.tessera.loop_subdivide(levels=2) == {"FINISHED"}
    assert "BakedLight" in bpy.context.active_object.data.color_attributes


def _state(bpy, ob):
    """What the user's file holds: every block's name, and the source's render visibility and selection."""
    names = {k: sorted(x.name for x in getattr(bpy.data, k)) for k in ("objects", "meshes", "materials", "images")}
    return names, ob.hide_render, [o.name for o in bpy.context.selected_objects], bpy.context.active_object.name


def _start_lit_bake(bpy, addon_module, depth, samples):
    """The lit scene's sphere subdivided to ``depth`` and its light bake started: (object, subdivision, the file's
    state before the start, the `BakeJob`)."""
    ob = lit_scene(bpy, addon_module("addon.compat"))
    arrays, _ = addon_module("addon.bridge").read_mesh(ob.data)
    sub = addon_module("kernels.subdivision.loop").loop_subdivide(arrays.positions, arrays.triangles, depth)
    before = _state(bpy, ob)
    bj = addon_module("addon.subdivision.bake").start_bake(
        bpy.context, ob, sub.positions, sub.triangles, np.zeros(len(sub.triangles), np.int32), samples, True, 2**30)
    return ob, sub, before, bj


def test_the_lighting_bake_runs_in_a_worker_and_changes_nothing_of_the_users_until_it_is_read(
        clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    ob, sub, before, bj = _start_lit_bake(bpy, addon_module, depth=1, samples=2)
    bake, jobs = addon_module("addon.subdivision.bake"), addon_module("addon.render_jobs")
    assert _state(bpy, ob) == before  # the copy, its materials and image went to the job's file only
    assert os.path.isdir(bj.job.folder) and bj.job.folder in jobs.open_folders()
    lines = []
    bj.job.wait(lines.append, "Baking lighting", timeout=300)
    assert lines[-1] == "Tessera: Baking lighting 1/1" and bj.job.device() == "CPU"
    colours = bake.read_bake(bj)
    assert colours.shape == (len(sub.triangles), 4) and (colours[:, 3] == 1).all() and colours[:, :3].max() > 0.05
    assert not os.path.exists(bj.job.folder) and not jobs.open_folders()
    assert "tessera_hce" not in ob.data  # only the operator stores a bake


def test_a_cancelled_lighting_bake_leaves_nothing(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    ob, _, before, bj = _start_lit_bake(bpy, addon_module, depth=2, samples=4096)
    bj.job.cancel()
    assert bj.job.process.poll() is not None and not os.path.exists(bj.job.folder)
    assert not addon_module("addon.render_jobs").open_folders() and _state(bpy, ob) == before


def test_a_lighting_bake_too_large_for_the_budget_is_refused_before_it_starts(clean_scene, bpy_module,
                                                                              addon_module):
    bpy = bpy_module
    ob = lit_scene(bpy, addon_module("addon.compat"))
    prefs = addon_module("addon.preferences").get_preferences()
    kept = prefs.memory_budget_mb
    prefs.memory_budget_mb = 1
    try:
        with pytest.raises(RuntimeError, match="Baking the light of 1,280 triangles") as err:
            bpy.ops.tessera.bake_lighting_hce(depth=3)
        assert "a lower Depth" in str(err.value)
    finally:
        prefs.memory_budget_mb = kept
    assert not addon_module("addon.render_jobs").open_folders() and "tessera_hce" not in ob.data


def test_the_ui_path_of_the_lighting_bake_stores_the_bake_or_cancels_cleanly(clean_scene, bpy_module, addon_module):
    """The modal path (timer polls, colours read and encoded on a worker thread, then stored) gives the bake the
    script path gives; Esc stops the worker and changes nothing."""
    bpy = bpy_module
    ob = lit_scene(bpy, addon_module("addon.compat"))
    assert bpy.ops.tessera.bake_lighting_hce(depth=1, samples=2) == {"FINISHED"}
    want = bytes(ob.data["tessera_hce"])
    del ob.data["tessera_hce"]
    op = UiOperator(bpy, "tessera.bake_lighting_hce", depth=1, samples=2)
    op._job, op._encoding = None, None
    assert op._begin_all(bpy.context) == {"FINISHED"} and op._job is not None
    assert op.drive(bpy.context) == {"FINISHED"}
    assert bytes(ob.data["tessera_hce"]) == want  # the same Cycles bake, encoded on a thread
    assert any("Baked lighting on CPU" in text for _, text in op.reports)
    del ob.data["tessera_hce"]
    op = UiOperator(bpy, "tessera.bake_lighting_hce", depth=2, samples=4096)
    op._job, op._encoding = None, None
    op._begin_all(bpy.context)
    assert op.drive(bpy.context, escape_after=2) == {"CANCELLED"}
    assert op._job.job.process.poll() is not None and not os.path.exists(op._job.job.folder)
    assert "tessera_hce" not in ob.data and not addon_module("addon.render_jobs").open_folders()


def test_the_redo_panel_bakes_again_only_when_the_render_changes(clean_scene, bpy_module, addon_module, monkeypatch):
    """Normals and Colour Tolerance re-encode the last bake's colours; a moved object nearby (its bounced light) or
    more samples render again."""
    bpy = bpy_module
    jobs = addon_module("addon.render_jobs")
    started = []
    real = jobs.start_worker
    monkeypatch.setattr(jobs, "start_worker", lambda *a: started.append(1) or real(*a))
    ob = lit_scene(bpy, addon_module("addon.compat"))
    for normals in (2, 0, 3):
        assert bpy.ops.tessera.bake_lighting_hce(depth=1, samples=2, normals=normals) == {"FINISHED"}
    assert len(started) == 1
    reused = bytes(ob.data["tessera_hce"])
    bpy.data.objects["Plane"].location.x += 0.8  # the red wall the light bounces off moved closer
    select_only(bpy, ob)
    assert bpy.ops.tessera.bake_lighting_hce(depth=1, samples=2, normals=3) == {"FINISHED"}
    assert len(started) == 2 and bytes(ob.data["tessera_hce"]) != reused
    bpy.data.objects["Plane"].location.x -= 0.8
    select_only(bpy, ob)
    assert bpy.ops.tessera.bake_lighting_hce(depth=1, samples=2, normals=3) == {"FINISHED"}
    assert len(started) == 3 and bytes(ob.data["tessera_hce"]) == reused  # rendered again: the same bytes
    assert bpy.ops.tessera.bake_lighting_hce(depth=1, samples=3, normals=3) == {"FINISHED"}
    assert len(started) == 4
    # every bake stored whole (Blender cut a bytes property replaced in place at its first zero byte)
    hce = addon_module("kernels.subdivision.hce")
    arrays, _ = addon_module("addon.bridge").read_mesh(ob.data)
    assert len(ob.data["tessera_hce"]) > 1000
    assert len(hce.unpack_container(ob.data["tessera_hce"], arrays.triangles).node_start) == len(arrays.triangles) + 1


def test_bake_lighting_bakes_every_selected_mesh(clean_scene, bpy_module, addon_module):
    """As Blender's own object operators: every selected mesh gets its light (the active one first); a selected
    light is not a mesh and is left alone; a mesh that cannot be baked fails the run and leaves the others as they
    were (one transaction)."""
    bpy = bpy_module
    ob = lit_scene(bpy, addon_module("addon.compat"))
    bpy.ops.mesh.primitive_cube_add(size=0.6, location=(0.8, 0.8, 0))
    cube = bpy.context.active_object
    light = next(o for o in bpy.data.objects if o.type == "LIGHT")
    for o in (ob, light, cube):
        o.select_set(True)
    bpy.context.view_layer.objects.active = ob
    assert bpy.ops.tessera.bake_lighting_hce(depth=1, samples=1) == {"FINISHED"}
    assert "tessera_hce" in ob.data and "tessera_hce" in cube.data
    del ob.data["tessera_hce"], cube.data["tessera_hce"]
    empty = bpy.data.objects.new("No Faces", bpy.data.meshes.new("No Faces"))
    bpy.context.scene.collection.objects.link(empty)
    empty.select_set(True)
    bpy.context.view_layer.objects.active = ob  # baked first, then undone when the empty mesh is refused
    with pytest.raises(RuntimeError, match="No Faces|no faces"):
        bpy.ops.tessera.bake_lighting_hce(depth=1, samples=1)
    assert "tessera_hce" not in ob.data and "tessera_hce" not in cube.data

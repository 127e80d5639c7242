"""Tessera's node groups as an asset library (tier: blender): one "Tessera" library on enable, none after
disable, never a duplicate; the .blend holds every group as an asset in Tessera's catalogs; nothing is left in
the open file; groups flagged as modifiers; `tessera.node_group_add`."""

import re

import pytest
from ui_rules import description_problems, jargon

pytestmark = pytest.mark.blender

#: Group inputs whose names read like a length, an angle or a factor, and the subtype that shows their unit.
SOCKET_SUBTYPES = ((re.compile(r"Tile Size|Width"), ("PIXEL", "NONE")),  # 4.2 has no PIXEL sockets
                   (re.compile(r"Radius|Distance|Size|Height Scale"), ("DISTANCE",)),
                   (re.compile(r"Field of View"), ("ANGLE",)),
                   (re.compile(r"Shape Factor"), ("FACTOR",)))


def entries(bpy):
    return [lib for lib in bpy.context.preferences.filepaths.asset_libraries if lib.name == "Tessera"]


def test_library_registered_once_and_removed_on_disable(clean_scene, bpy_module, addon, addon_module, tmp_path):
    import addon_utils

    bpy = bpy_module
    lib = addon_module("addon.node_library")
    groups = addon_module("addon.node_groups")
    assert len(entries(bpy)) == 1
    directory = entries(bpy)[0].path
    blend = lib.library_file(directory)
    assert blend.exists() and (blend.parent / lib.CATALOG_FILE).exists()
    catalogs = (blend.parent / lib.CATALOG_FILE).read_text()
    assert "VERSION 1" in catalogs and ":Tessera/Tessellation:" in catalogs
    with bpy.data.libraries.load(str(blend), assets_only=True) as (src, _):
        names = set(src.node_groups)
    available = {s.name for s in groups.GROUPS.values() if s.available is None or s.available() is None}
    assert "Tessera Phong" in names and names == available
    before = {tree.name: tree.asset_data for tree in bpy.data.node_groups}
    written = lib.write_library(tmp_path)  # writing the library leaves the open file as it was
    assert written.exists() and {t.name: t.asset_data for t in bpy.data.node_groups} == before
    name = addon.__name__
    addon_utils.disable(name, default_set=True)
    try:
        assert entries(bpy) == []
    finally:
        addon_utils.enable(name, default_set=True)
    addon_utils.enable(name, default_set=True)
    assert len(entries(bpy)) == 1 and entries(bpy)[0].path == directory


def test_a_worker_blender_writes_the_library_and_the_entry_follows(clean_scene, bpy_module, addon, addon_module,
                                                                   tmp_path, capsys):
    """With a window the library is written by a worker Blender (`node_library_worker.py`), polled by a timer: the
    files it writes are the library the add-on itself writes (the same groups), and the entry points there when it is
    done; nothing of the job is left."""
    import time

    bpy = bpy_module
    lib = addon_module("addon.node_library")
    directory = entries(bpy)[0].path
    try:
        assert lib._start_writer(tmp_path)
        job = lib._writer["job"]
        deadline = time.monotonic() + 240
        while lib._poll_writer() is not None and time.monotonic() < deadline:
            time.sleep(0.25)
        assert not lib._writer and not job.running()
        assert "writing it here" not in capsys.readouterr().out  # the worker wrote it, not the fallback
        assert lib._complete(tmp_path) and entries(bpy)[0].path == str(tmp_path)
        with bpy.data.libraries.load(str(lib.library_file(tmp_path)), assets_only=True) as (src, _):
            written = set(src.node_groups)
        with bpy.data.libraries.load(str(lib.library_file(directory)), assets_only=True) as (src, _):
            assert written == set(src.node_groups) and len(written) >= 5
        assert not (tmp_path / "job.json").exists() and not lib.Path(job.folder).exists()
    finally:
        lib._point_entry(directory)


def test_the_assets_describe_themselves(clean_scene, bpy_module, addon, addon_module):
    """Every group in the library: a one-sentence description (its tooltip and its asset's), the asset's author,
    license and copyright from the manifest, a catalog under Tessera, flagged for Add Modifier; every socket with a
    tooltip in plain words and the subtype of its unit."""
    bpy = bpy_module
    lib = addon_module("addon.node_library")
    manifest = addon_module("addon.manifest").manifest()
    blend = lib.library_file(entries(bpy)[0].path)
    catalogs = (blend.parent / lib.CATALOG_FILE).read_text()
    with bpy.data.libraries.load(str(blend), assets_only=True) as (src, dst):
        dst.node_groups = list(src.node_groups)
    try:
        assert len(dst.node_groups) >= 5
        for tree in dst.node_groups:
            assert not description_problems(tree.description) and not jargon(tree.description), tree.name
            asset = tree.asset_data
            assert asset.description == tree.description
            assert asset.author == manifest["maintainer"] and asset.license == "GPL-3.0-or-later"
            assert asset.copyright == manifest["copyright"][0]
            assert f"{asset.catalog_id}:Tessera/" in catalogs, tree.name
            assert tree.is_modifier, tree.name
            for item in tree.interface.items_tree:
                if item.item_type != "SOCKET":
                    continue
                where = f"{tree.name} › {item.name}"
                assert item.description and not jargon(item.description), where
                if item.in_out != "INPUT" or item.socket_type not in ("NodeSocketFloat", "NodeSocketInt"):
                    continue
                for pattern, subtypes in SOCKET_SUBTYPES:
                    if pattern.search(item.name):
                        assert item.subtype in subtypes, f"{where}: {item.subtype}"
                        break
    finally:
        for tree in dst.node_groups:
            bpy.data.node_groups.remove(tree)


def test_node_group_add_puts_the_group_on_the_selection(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    bpy.ops.mesh.primitive_cube_add()
    bpy.ops.mesh.primitive_monkey_add(location=(3, 0, 0))
    for ob in bpy.data.objects:
        ob.select_set(True)
    assert bpy.ops.tessera.node_group_add(group="Tessera Phong") == {"FINISHED"}
    tree = bpy.data.node_groups["Tessera Phong"]
    assert all(ob.modifiers[-1].node_group == tree for ob in bpy.data.objects)
    assert tree.get("tessera_version") == addon_module("addon.tessellation.phong_nodes").VERSION
    assert tree.is_modifier
    descriptions = {i.name: i.description for i in tree.interface.items_tree if i.item_type == "SOCKET"}
    assert all(descriptions.values()) and {"Subdivisions", "Shape Factor"} <= set(descriptions)
    bpy.data.node_groups.remove(tree)


FARM = """
import sys, bpy, numpy as np
bpy.ops.wm.open_mainfile(filepath=sys.argv[1])
assert not any('tessera' in name for name in bpy.context.preferences.addons.keys()), 'the add-on is enabled'
dg = bpy.context.evaluated_depsgraph_get()
out = {}
for ob in bpy.data.objects:
    if ob.type == 'CAMERA':
        continue
    me = ob.evaluated_get(dg).to_mesh()
    pos = np.empty(len(me.vertices) * 3, np.float32)
    me.attributes['position'].data.foreach_get('vector', pos)
    out[ob.name] = pos.reshape(-1, 3)
np.savez(sys.argv[2], **out)
"""


def farm_scene(bpy, addon_module):
    """One object per Tessera group, each with its group as a modifier; returns their evaluated positions."""
    import numpy as np

    ng = addon_module("addon.node_groups")
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=2)
    bpy.context.active_object.name = "Phong"
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=2, location=(3, 0, 0))
    bpy.context.active_object.name = "PN"
    bpy.ops.curve.primitive_bezier_curve_add(location=(0, 3, 0))
    bpy.context.active_object.name = "Tubes"
    bpy.ops.mesh.primitive_uv_sphere_add(location=(3, 3, 0))
    bpy.context.active_object.name = "Displace"
    image = bpy.data.images.new("Farm Map", 8, 8)  # 8-bit, packed as PNG: what is saved is what was shown
    rgba = np.random.default_rng(2).uniform(0, 1, (8 * 8, 4)).astype(np.float32)
    rgba[:, 3] = 1.0  # opaque: this test is about the groups, not how a PNG keeps transparent texels
    image.pixels.foreach_set(rgba.ravel())
    image.update()
    image.pack()
    heights = bpy.data.images.new("Farm Heights", 33, 33)
    texels = np.random.default_rng(3).uniform(0, 1, (33 * 33, 4)).astype(np.float32)
    texels[:, 3] = 1.0
    heights.pixels.foreach_set(texels.ravel())
    heights.update()
    heights.pack()
    terrain = bpy.data.objects.new("Terrain", bpy.data.meshes.new("Terrain"))
    bpy.context.scene.collection.objects.link(terrain)
    bpy.ops.object.camera_add(location=(-9, -9, 6))  # the terrain's levels follow the active camera
    bpy.context.scene.camera = bpy.context.active_object
    bpy.context.active_object.name = "Camera"
    inputs = {"Phong": {"Subdivisions": 2}, "PN": {"Subdivisions": 2, "Sharp Edges": "Split"},
              "Tubes": {"Caps": "Round", "Sides": 6}, "Displace": {"Map": "Height", "Image": image,
                                                                   "Strength": 0.2},
              "Terrain": {"Image": heights, "Tile Size": 8, "Detail Distance": 8.0, "Height Scale": 3.0}}
    for name, spec in (("Phong", "tessera.phong_nodes"), ("PN", "tessera.pn_nodes"), ("Tubes", "tubes.nodes"),
                       ("Displace", "displacement.nodes"), ("Terrain", "terrain.nodes")):
        ob = bpy.data.objects[name]
        mod = ob.modifiers.new(name, "NODES")
        mod.node_group = ng.ensure_group(addon_module(f"addon.{spec.replace('tessera.', 'tessellation.')}").SPEC)
        ng.set_inputs(mod, inputs[name])
    meshes = [ob for ob in bpy.data.objects if ob.type != "CAMERA"]
    assert {ob.modifiers[-1].node_group.name for ob in meshes} == set(ng.GROUPS)
    dg = bpy.context.evaluated_depsgraph_get()
    out = {}
    for ob in meshes:
        me = ob.evaluated_get(dg).to_mesh()
        out[ob.name] = np.array([v.co for v in me.vertices], np.float32)
        ob.evaluated_get(dg).to_mesh_clear()
    return out


def test_a_file_using_every_group_evaluates_the_same_without_the_add_on(clean_scene, bpy_module, addon_module,
                                                                       tmp_path):
    """Saved with every group, the file evaluates to the same geometry in a Blender with no Tessera (the render
    farm); reopened with the add-on, its groups are kept as they are (no rebuild, no second copy)."""
    import os
    import subprocess
    import sys

    import numpy as np

    bpy = bpy_module
    here = farm_scene(bpy, addon_module)
    for tree in bpy.data.node_groups:
        tree.nodes[0].label = "kept"  # a rebuilt group would lose it
    path = tmp_path / "farm.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    out = tmp_path / "farm.npz"
    env = dict(os.environ, BLENDER_USER_RESOURCES=str(tmp_path / "farm_user"))  # a user folder with no Tessera
    proc = subprocess.run([sys.executable, "-c", FARM, str(path), str(out)], capture_output=True, text=True,
                          env=env, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    farm = dict(np.load(out))
    assert set(farm) == set(here)
    for name, pos in here.items():
        assert farm[name].shape == pos.shape and np.array_equal(farm[name], pos), name
        assert len(pos) > 0
    ng = addon_module("addon.node_groups")
    names = {tree.name for tree in bpy.data.node_groups}
    bpy.ops.wm.open_mainfile(filepath=str(path))
    assert entries(bpy) and len(entries(bpy)) == 1
    for spec in ng.GROUPS.values():
        tree = ng.ensure_group(spec)
        assert tree.nodes[0].label == "kept", spec.name
    assert {tree.name for tree in bpy.data.node_groups} == names


def test_a_group_input_named_like_a_tessellate_setting_means_the_same(bpy_module, addon_module):
    """One word, one meaning across the operator and the node groups: the groups' Subdivisions counts Subdivide Mesh
    passes (each splits every edge in two), the operator's Level counts segments per edge, so no group input is
    called Level; the inputs the two do share (Shape Factor, Sharp Edges) take the operator's meaning and slider."""
    bpy = bpy_module
    ng = addon_module("addon.node_groups")
    op = {p.name: p for p in bpy.ops.tessera.tessellate.get_rna_type().properties}
    for spec in ("tessellation.phong_nodes", "tessellation.pn_nodes"):
        tree = ng.ensure_group(addon_module(f"addon.{spec}").SPEC)
        try:
            inputs = {i.name: i for i in tree.interface.items_tree if i.item_type == "SOCKET" and i.in_out == "INPUT"}
            assert "Subdivisions" in inputs and "Level" not in inputs and "Level" in op
            shared = set(inputs) & set(op)
            assert shared <= {"Shape Factor", "Sharp Edges"}, shared
            if "Shape Factor" in shared:
                assert (inputs["Shape Factor"].min_value, inputs["Shape Factor"].max_value) == (
                    op["Shape Factor"].soft_min, op["Shape Factor"].soft_max)  # the slider the operator shows
        finally:
            bpy.data.node_groups.remove(tree)

"""Tessera's node groups as an asset library (tier: blender): one "Tessera" library on enable, none after
disable, never a duplicate; the .blend holds every group as an asset in Tessera's catalogs; nothing is left in
the open file; groups flagged as modifiers; `tessera.node_group_add`."""

import pytest

pytestmark = pytest.mark.blender


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
    assert all(descriptions.values()) and {"Level", "Shape Factor"} <= set(descriptions)
    bpy.data.node_groups.remove(tree)

"""The ``tessera`` pointers on Object, Scene and Image, the options shared by operators and objects, and the
preview caches (keyed by session_uid, invalidated by settings without the settings importing previews)."""

import pytest

pytestmark = pytest.mark.blender

OPTIONS = (  # (settings module, options class, operator, object group)
    ("addon.tessellation.settings", "TessellateOptions", "tessellate", "tessellate"),
    ("addon.tubes.settings", "TubeOptions", "tubes", "tubes"),
    ("addon.terrain.settings", "TerrainOptions", "terrain_add", "terrain"),
    ("addon.subdivision.settings", "LoopOptions", "loop_subdivide", "loop"),
    ("addon.surfaces.settings", "ParametricOptions", "parametric_surface_add", "surface"),
)


def test_one_tessera_pointer_per_id_type(bpy_module, addon):
    bpy = bpy_module
    assert {"tessellate", "tubes", "displacement", "terrain"} <= set(bpy.types.Object.bl_rna.properties["tessera"]
                                                                     .fixed_type.properties.keys())
    assert "brush" in bpy.context.scene.tessera.bl_rna.properties
    assert bpy.context.scene.tessera.brush.radius > 0
    image = bpy.data.images.new("props_probe", 4, 4)
    try:
        assert image.tessera.serial == 0
        image.tessera.serial = 3
        assert image.tessera.serial == 3
    finally:
        bpy.data.images.remove(image)
    assert not hasattr(bpy.types.Scene, "tessera_brush") and "tessera_serial" not in bpy.types.Image.bl_rna.properties


@pytest.mark.parametrize("module, options, operator, group", OPTIONS)
def test_operators_and_objects_share_one_option_definition(bpy_module, addon_module, module, options, operator,
                                                           group):
    """Every option declared on the options class is a property of the operator (redo panel) and of the object's
    settings group, with the same type and default (the one scaffold, `addon.settings_scaffold`)."""
    bpy = bpy_module
    names = addon_module("addon.settings_scaffold").option_names(getattr(addon_module(module), options))
    assert len(names) >= 4
    op_props = getattr(bpy.ops.tessera, operator).get_rna_type().properties
    group_props = bpy.types.Object.bl_rna.properties["tessera"].fixed_type.properties[group].fixed_type.properties
    for name in names:
        a, b = op_props[name], group_props[name]
        assert a.type == b.type, name
        if a.type in ("FLOAT", "INT", "BOOLEAN") and not getattr(a, "is_array", False):
            assert a.default == b.default, name
        elif a.type in ("ENUM", "STRING"):
            assert (a.default_flag if a.type == "ENUM" and a.is_enum_flag else a.default) == (
                b.default_flag if b.type == "ENUM" and b.is_enum_flag else b.default), name


@pytest.mark.gpu
def test_preview_cache_follows_renames_and_settings_changes(gpu_renderer, clean_scene, bpy_module, addon_module):
    """Entries are keyed by session_uid (a rename keeps them); a settings change reaches the preview through the
    invalidation topic and drops the entry; the terrain settings module does not import its preview."""
    bpy = bpy_module
    preview = addon_module("addon.tubes.preview")
    viewport = addon_module("addon.viewport")
    bpy.ops.curve.primitive_bezier_circle_add()
    ob = bpy.context.active_object
    ob.tessera.tubes.preview = True
    bpy.context.view_layer.update()
    entry = preview.entry_for(ob)
    assert entry is not None and ob in preview.PREVIEW.cache
    ob.name = "renamed circle"
    assert preview.entry_for(ob) is entry  # the same upload, found under the new name
    seen = []
    viewport.subscribe("tubes", seen.append)
    try:
        ob.tessera.tubes.radius = 0.2
    finally:
        viewport.unsubscribe("tubes", seen.append)
    assert seen == [ob] and ob not in preview.PREVIEW.cache
    ob.tessera.tubes.preview = False
    viewport.clear_previews()
    assert not preview.PREVIEW.cache.entries

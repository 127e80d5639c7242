"""Menu entries where Blender users look for them: creators under Add › Tessera, tools on the active object under
Object › Tessera, file writers under File › Export.

The entries are data (`ADD_MENU`, `OBJECT_MENU`, `EXPORT_MENU`): the menus, the sidebar's start panel and the test
that resolves every menu path named in messages and docs read the same lists.
"""

import bpy

#: Operators that make something new from nothing (no object selected needed): Add › Tessera.
ADD_MENU = ("tessera.parametric_surface_add", "tessera.terrain_add", "tessera.vector_field_texture")
#: Operators on the active or selected objects: Object › Tessera (``tessera.node_group_add`` as a submenu of groups).
OBJECT_MENU = (
    "tessera.tessellate", "tessera.loop_subdivide", "tessera.bake_lighting_hce", "tessera.tubes",
    "tessera.displacement_add", "tessera.terrain_bake", "tessera.curve_adaptive", "tessera.surface_tessellate",
    "tessera.impostor_bake", "tessera.node_group_add",
)
#: Operators that write files: File › Export, as (operator, menu text or None for the operator's own label).
EXPORT_MENU = (
    ("tessera.impostor_export", None),
    ("tessera.displacement_export", "Tessera Displacement Map (.exr, .png, .tif)"),
)
#: The operators drawn as a submenu of one of their enum properties.
ENUM_MENUS = {"tessera.node_group_add": "group"}

ICONS = {
    "tessera.parametric_surface_add": "SURFACE_NSURFACE", "tessera.terrain_add": "RNDCURVE",
    "tessera.vector_field_texture": "FORCE_VORTEX", "tessera.tessellate": "MOD_SUBSURF",
    "tessera.loop_subdivide": "MOD_SUBSURF", "tessera.bake_lighting_hce": "LIGHT_SUN", "tessera.tubes": "MESH_CYLINDER",
    "tessera.displacement_add": "IMAGE_DATA", "tessera.terrain_bake": "VIEW_CAMERA",
    "tessera.curve_adaptive": "CURVE_BEZCURVE", "tessera.surface_tessellate": "SURFACE_NSURFACE",
    "tessera.impostor_bake": "IMAGE_PLANE", "tessera.node_group_add": "GEOMETRY_NODES",
}


def draw_entries(layout, entries):
    """One menu item per operator of ``entries`` (ids, or (id, text) pairs)."""
    for entry in entries:
        idname, text = entry if isinstance(entry, tuple) else (entry, None)
        if idname in ENUM_MENUS:
            layout.operator_menu_enum(idname, ENUM_MENUS[idname], icon=ICONS.get(idname, "NONE"))
        elif text is None:
            layout.operator(idname, icon=ICONS.get(idname, "NONE"))
        else:
            layout.operator(idname, text=text, icon=ICONS.get(idname, "NONE"))


class TESSERA_MT_object(bpy.types.Menu):
    bl_idname = "TESSERA_MT_object"
    bl_label = "Tessera"
    bl_description = "Tessera's tools for the active object"

    def draw(self, context):
        draw_entries(self.layout, OBJECT_MENU)


class TESSERA_MT_add(bpy.types.Menu):
    bl_idname = "TESSERA_MT_add"
    bl_label = "Tessera"
    bl_description = "Add surfaces, terrains and flow textures made by Tessera"

    def draw(self, context):
        self.layout.operator_context = "INVOKE_REGION_WIN"
        draw_entries(self.layout, ADD_MENU)


def draw_add_menu(self, context):
    self.layout.separator()
    self.layout.menu(TESSERA_MT_add.bl_idname, icon="MOD_SUBSURF")


def draw_object_menu(self, context):
    self.layout.separator()
    self.layout.menu(TESSERA_MT_object.bl_idname)


def draw_export_menu(self, context):
    self.layout.operator_context = "INVOKE_DEFAULT"
    draw_entries(self.layout, EXPORT_MENU)


classes = (TESSERA_MT_object, TESSERA_MT_add)
_register, _unregister = bpy.utils.register_classes_factory(classes)
#: Blender's menus and what Tessera appends to each.
_HOOKS = (("VIEW3D_MT_object", draw_object_menu), ("VIEW3D_MT_add", draw_add_menu),
          ("TOPBAR_MT_file_export", draw_export_menu))


def register():
    _register()
    for menu, hook in _HOOKS:
        getattr(bpy.types, menu).append(hook)


def unregister():
    for menu, hook in reversed(_HOOKS):
        getattr(bpy.types, menu).remove(hook)
    _unregister()

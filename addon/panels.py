"""Sidebar panel: View3D > Sidebar > Tessera. Edits the settings stored on the object and runs them."""

import bpy

from .displacement import nodes as displace_nodes
from .displacement.brush_tool import draw_brush_settings
from .terrain.settings import draw_terrain_settings
from .tessellation.settings import draw_settings
from .tubes.settings import copy_tube_settings, draw_tube_settings
from .tubes.sources import SOURCE_TYPES


class _Sidebar:
    """Where Tessera's panels live: View3D > Sidebar > Tessera. Shown for active objects of ``object_types``."""

    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Tessera"
    object_types = frozenset({"MESH"})

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        return ob is not None and ob.type in cls.object_types


class TESSERA_PT_tessellate(_Sidebar, bpy.types.Panel):
    bl_idname = "TESSERA_PT_tessellate"
    bl_label = "Tessellate"

    def draw(self, context):
        settings = context.active_object.tessera.tessellate
        self.layout.prop(settings, "preview", icon="HIDE_OFF")
        draw_settings(self.layout, settings)
        row = self.layout.row()
        row.scale_y = 1.4
        op = row.operator("tessera.tessellate", icon="MOD_SUBSURF")
        op.use_object_settings = True


class TESSERA_PT_tubes(_Sidebar, bpy.types.Panel):
    bl_idname = "TESSERA_PT_tubes"
    bl_label = "Tubes"
    object_types = frozenset(SOURCE_TYPES)

    def draw_header(self, context):
        self.layout.prop(context.active_object.tessera.tubes, "preview", text="")

    def draw(self, context):
        settings = context.active_object.tessera.tubes
        draw_tube_settings(self.layout, settings)
        row = self.layout.row()
        row.scale_y = 1.4
        op = row.operator("tessera.tubes", icon="MESH_CYLINDER", text="Make Tube Mesh")
        copy_tube_settings(settings, op)


class TESSERA_PT_displacement(_Sidebar, bpy.types.Panel):
    bl_idname = "TESSERA_PT_displacement"
    bl_label = "Displacement Map"

    def draw(self, context):
        layout = self.layout
        settings = context.active_object.tessera.displacement
        if settings.image is None:
            layout.operator("tessera.displacement_add", icon="IMAGE_DATA")
            return
        layout.use_property_split = True
        layout.use_property_decorate = False
        layout.prop(settings, "image")
        layout.prop(settings, "mode")
        if settings.mode == "VECTOR":
            layout.prop(settings, "space")
            if settings.space == "TANGENT" and not displace_nodes.available():
                layout.label(text="Tangent space needs Blender 5.0 or newer: the map is not shown", icon="ERROR")
        layout.prop_search(settings, "uv_map", context.active_object.data, "uv_layers")
        layout.prop(settings, "mid_level")
        layout.prop(settings, "strength")
        row = layout.row()
        row.operator("tessera.displacement_export", icon="EXPORT")
        box = layout.box()
        box.label(text="Brush (Displacement Brush tool)", icon="BRUSH_DATA")
        draw_brush_settings(box, context.scene.tessera_brush, 1 if settings.mode == "HEIGHT" else 3)
        box = layout.box()
        box.label(text="Custom Kernel", icon="SCRIPT")
        box.prop(settings, "kernel_text", text="")
        if settings.kernel_text is not None:
            box.prop(settings, "kernel_args")
            row = box.row()
            row.operator("tessera.displacement_trust_kernel", icon="LOCKED")
            row.operator("tessera.displacement_custom", icon="PLAY")


class TESSERA_PT_terrain(_Sidebar, bpy.types.Panel):
    bl_idname = "TESSERA_PT_terrain"
    bl_label = "Terrain"

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        return ob is not None and ob.tessera.terrain.is_terrain

    def draw_header(self, context):
        self.layout.prop(context.active_object.tessera.terrain, "preview", text="")

    def draw(self, context):
        draw_terrain_settings(self.layout, context.active_object.tessera.terrain)
        row = self.layout.row()
        row.scale_y = 1.4
        row.operator("tessera.terrain_bake", icon="VIEW_CAMERA")


classes = (TESSERA_PT_tessellate, TESSERA_PT_tubes, TESSERA_PT_displacement, TESSERA_PT_terrain)
register, unregister = bpy.utils.register_classes_factory(classes)

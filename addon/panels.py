"""Sidebar panel: View3D > Sidebar > Tessera. Edits the settings stored on the object and runs them."""

import bpy

from .settings import draw_settings
from .tube_settings import copy_tube_settings, draw_tube_settings
from .tube_sources import SOURCE_TYPES


class _Sidebar:
    """Where Tessera's panels live: View3D > Sidebar > Tessera."""

    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Tessera"


class TESSERA_PT_tessellate(_Sidebar, bpy.types.Panel):
    bl_idname = "TESSERA_PT_tessellate"
    bl_label = "Tessellate"

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        return ob is not None and ob.type == "MESH"

    def draw(self, context):
        settings = context.active_object.tessera.tessellate
        draw_settings(self.layout, settings)
        row = self.layout.row()
        row.scale_y = 1.4
        op = row.operator("tessera.tessellate", icon="MOD_SUBSURF")
        op.use_object_settings = True


class TESSERA_PT_tubes(_Sidebar, bpy.types.Panel):
    bl_idname = "TESSERA_PT_tubes"
    bl_label = "Tubes"

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        return ob is not None and ob.type in SOURCE_TYPES

    def draw_header(self, context):
        self.layout.prop(context.active_object.tessera.tubes, "preview", text="")

    def draw(self, context):
        settings = context.active_object.tessera.tubes
        draw_tube_settings(self.layout, settings)
        row = self.layout.row()
        row.scale_y = 1.4
        op = row.operator("tessera.tubes", icon="MESH_CYLINDER", text="Make Tube Mesh")
        copy_tube_settings(settings, op)


classes = (TESSERA_PT_tessellate, TESSERA_PT_tubes)
register, unregister = bpy.utils.register_classes_factory(classes)

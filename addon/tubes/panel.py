"""Sidebar panel Tessera > Tubes: the object's tube settings, the preview toggle, and the mesh operator."""

import bpy

from ..sidebar import Sidebar, active_object
from .settings import copy_tubes_settings, draw_tubes_settings
from .sources import SOURCE_TYPES


class TESSERA_PT_tubes(Sidebar, bpy.types.Panel):
    bl_idname = "TESSERA_PT_tubes"
    bl_label = "Tubes"
    object_types = frozenset(SOURCE_TYPES)

    def draw_header(self, context):
        self.layout.prop(active_object(context).tessera.tubes, "preview", text="")

    def draw(self, context):
        settings = active_object(context).tessera.tubes
        draw_tubes_settings(self.layout, settings)
        row = self.layout.row()
        row.scale_y = 1.4
        op = row.operator("tessera.tubes", icon="MESH_CYLINDER", text="Make Tube Mesh")
        copy_tubes_settings(settings, op)


classes = (TESSERA_PT_tubes,)
register, unregister = bpy.utils.register_classes_factory(classes)

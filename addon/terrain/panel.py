"""Sidebar panel Tessera > Terrain: a terrain object's settings, the preview toggle, and the bake."""

import bpy

from ..sidebar import Sidebar, active_object, panel_order, preview_notice
from .settings import draw_terrain_settings


class TESSERA_PT_terrain(Sidebar, bpy.types.Panel):
    bl_idname = "TESSERA_PT_terrain"
    bl_order = panel_order(bl_idname)
    bl_label = "Terrain"

    @classmethod
    def poll(cls, context):
        ob = active_object(context)
        return ob is not None and ob.tessera.terrain.is_terrain

    def draw_header(self, context):
        self.layout.prop(active_object(context).tessera.terrain, "preview", text="")

    def draw(self, context):
        preview_notice(self.layout, context, active_object(context).tessera.terrain.preview,
                       "bake it for the camera (Bake Terrain for Camera) or add the Tessera Terrain node group")
        draw_terrain_settings(self.layout, active_object(context).tessera.terrain)
        row = self.layout.row()
        row.scale_y = 1.4
        row.operator("tessera.terrain_bake", icon="VIEW_CAMERA")


classes = (TESSERA_PT_terrain,)
register, unregister = bpy.utils.register_classes_factory(classes)

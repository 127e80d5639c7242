"""Sidebar panel Tessera > Tessellate: edits the object's tessellation settings and runs them."""

import bpy

from ..sidebar import Sidebar, active_object, panel_order, preview_notice
from .settings import draw_settings


class TESSERA_PT_tessellation(Sidebar, bpy.types.Panel):
    bl_idname = "TESSERA_PT_tessellation"
    bl_order = panel_order(bl_idname)
    bl_label = "Tessellate"

    def draw(self, context):
        settings = active_object(context).tessera.tessellate
        self.layout.prop(settings, "preview", icon="HIDE_OFF")
        preview_notice(self.layout, context, settings.preview, "apply it (Tessellate) or add the Tessera PN "
                       "Triangles or Phong node group")
        draw_settings(self.layout, settings)
        row = self.layout.row()
        row.scale_y = 1.4
        op = row.operator("tessera.tessellate", icon="MOD_SUBSURF")
        op.use_object_settings = True


classes = (TESSERA_PT_tessellation,)
register, unregister = bpy.utils.register_classes_factory(classes)

"""Sidebar panel: View3D > Sidebar > Tessera. Edits the settings stored on the object and runs them."""

import bpy

from .settings import draw_settings


class TESSERA_PT_tessellate(bpy.types.Panel):
    bl_idname = "TESSERA_PT_tessellate"
    bl_label = "Tessellate"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Tessera"

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


classes = (TESSERA_PT_tessellate,)
register, unregister = bpy.utils.register_classes_factory(classes)

"""Sidebar panel Tessera > Parametric Surface: a live surface's settings, its control points and factor, and Bake."""

import bpy

from ..sidebar import Sidebar, active_object, panel_order, preview_notice
from .settings import draw_surface_options


class TESSERA_PT_surfaces(Sidebar, bpy.types.Panel):
    bl_idname = "TESSERA_PT_surfaces"
    bl_order = panel_order(bl_idname)
    bl_label = "Parametric Surface"
    object_types = frozenset({"EMPTY"})

    @classmethod
    def poll(cls, context):
        return super().poll(context) and active_object(context).tessera.surface.is_surface

    def draw_header(self, context):
        self.layout.prop(active_object(context).tessera.surface, "is_surface", text="")

    def draw(self, context):
        s = active_object(context).tessera.surface
        layout = self.layout
        preview_notice(layout, context, s.is_surface, "bake it into a mesh (Bake Surface)")
        draw_surface_options(layout, s)
        col = layout.column()
        col.use_property_split = True
        col.prop(s, "instance_object")
        col.prop(s, "factor_mode")
        if s.factor_mode == "CAMERA":
            col.prop(s, "edge_pixels")
        row = layout.row()
        row.scale_y = 1.4
        row.operator("tessera.parametric_surface_bake", icon="MESH_DATA")


classes = (TESSERA_PT_surfaces,)
register, unregister = bpy.utils.register_classes_factory(classes)

"""Sidebar panel Tessera > Displacement Map: the object's map, the brush and the custom kernel."""

import bpy

from ..compat import UV_TANGENT_MESSAGE, has_uv_tangent_node
from ..sidebar import Sidebar, active_object, panel_order
from .brush_tool import draw_brush_settings


class TESSERA_PT_displacement(Sidebar, bpy.types.Panel):
    bl_idname = "TESSERA_PT_displacement"
    bl_order = panel_order(bl_idname)
    bl_label = "Displacement Map"

    def draw(self, context):
        layout = self.layout
        settings = active_object(context).tessera.displacement
        if settings.image is None:
            layout.operator("tessera.displacement_add", icon="IMAGE_DATA")
            return
        layout.use_property_split = True
        layout.use_property_decorate = False
        layout.prop(settings, "image")
        layout.prop(settings, "mode")
        if settings.mode == "VECTOR":
            layout.prop(settings, "space")
            if settings.space == "TANGENT" and not has_uv_tangent_node():
                layout.label(text=f"{UV_TANGENT_MESSAGE}: the map is not shown", icon="ERROR")
        layout.prop_search(settings, "uv_map", active_object(context).data, "uv_layers")
        layout.prop(settings, "mid_level")
        layout.prop(settings, "strength")
        row = layout.row()
        row.operator("tessera.displacement_export", icon="EXPORT")
        box = layout.box()
        box.label(text="Brush (Displacement Brush tool)", icon="BRUSH_DATA")
        draw_brush_settings(box, context.scene.tessera.brush, 1 if settings.mode == "HEIGHT" else 3)
        box = layout.box()
        box.label(text="Custom Kernel", icon="SCRIPT")
        box.prop(settings, "kernel_text", text="")
        if settings.kernel_text is not None:
            box.prop(settings, "kernel_args")
            row = box.row()
            row.operator("tessera.displacement_trust_kernel", icon="LOCKED")
            row.operator("tessera.displacement_custom", icon="PLAY")


classes = (TESSERA_PT_displacement,)
register, unregister = bpy.utils.register_classes_factory(classes)

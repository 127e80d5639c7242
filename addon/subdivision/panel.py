"""Sidebar panel Tessera > Loop Subdivision: the object's Loop settings, the preview toggle, what the mesh brings
(creases, baked lighting) and the operators."""

import bpy

from ..settings_scaffold import copy_options
from ..sidebar import Sidebar, active_object, panel_order, preview_notice
from .build import HCE_PROPERTY
from .settings import LoopOptions, draw_subdivision_settings


class TESSERA_PT_subdivision(Sidebar, bpy.types.Panel):
    bl_idname = "TESSERA_PT_subdivision"
    bl_order = panel_order(bl_idname)
    bl_label = "Loop Subdivision"
    bl_options = {"DEFAULT_CLOSED"}

    def draw_header(self, context):
        self.layout.prop(active_object(context).tessera.loop, "preview", text="")

    def draw(self, context):
        layout = self.layout
        ob = active_object(context)
        settings = ob.tessera.loop
        preview_notice(layout, context, settings.preview, "apply it (Loop Subdivide)")
        draw_subdivision_settings(layout, settings)
        me = ob.data
        col = layout.column(align=True)
        creases = [a.name for a in me.attributes if a.name in ("crease_edge", "sharp_edge", "crease_vert")]
        col.label(text="Creases: " + (", ".join(creases) if creases else "none"), icon="MOD_EDGESPLIT")
        baked = HCE_PROPERTY in me
        col.label(text="Baked lighting: " + ("stored" if baked else "none"), icon="LIGHT_SUN")
        layout.operator("tessera.bake_lighting_hce", icon="LIGHT_SUN",
                        text="Bake Lighting Again" if baked else "Bake Lighting")
        row = layout.row()
        row.scale_y = 1.4
        op = row.operator("tessera.loop_subdivide", icon="MOD_SUBSURF", text="Make Loop Mesh")
        copy_options(LoopOptions, settings, op)


classes = (TESSERA_PT_subdivision,)
register, unregister = bpy.utils.register_classes_factory(classes)

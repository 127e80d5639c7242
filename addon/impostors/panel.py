"""Sidebar panel Tessera > Nailboard: the object's nailboard switch and its settings."""

import bpy

from ..sidebar import Sidebar


class TESSERA_PT_impostors(Sidebar, bpy.types.Panel):
    bl_idname = "TESSERA_PT_impostors"
    bl_label = "Nailboard"
    bl_options = {"DEFAULT_CLOSED"}

    def draw_header(self, context):
        self.layout.prop(context.active_object.tessera.nailboard, "enabled", text="")

    def draw(self, context):
        s = context.active_object.tessera.nailboard
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        col = layout.column()
        for name in ("relief", "tolerance", "samples", "progressive", "lead"):
            col.prop(s, name)


classes = (TESSERA_PT_impostors,)
register, unregister = bpy.utils.register_classes_factory(classes)

"""Sidebar panel Tessera › Impostors: the object's live nailboard (drawn from a board Cycles renders in the
background) and the baked impostor card."""

import bpy

from ...kernels.common.errors import InvalidInputError
from .. import compat
from ..guarded import check_numbers
from ..sidebar import Sidebar, active_object, panel_order, preview_notice, wrapped_label
from .preview import MANAGER


class TESSERA_PT_impostors(Sidebar, bpy.types.Panel):
    bl_idname = "TESSERA_PT_impostors"
    bl_order = panel_order(bl_idname)
    bl_label = "Impostors"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        s = active_object(context).tessera.nailboard
        layout = self.layout
        preview_notice(layout, context, s.enabled, "bake an impostor card (Bake Impostor)")
        layout.use_property_split = True
        layout.use_property_decorate = False
        layout.prop(s, "enabled")
        col = layout.column()
        col.active = s.enabled
        for name in ("relief", "tolerance", "samples", "progressive", "lead"):
            col.prop(s, name)
        try:
            check_numbers(s)  # a script can store NaN; the preview then skips the object, and says why here
        except InvalidInputError as err:
            col.label(text=str(err), icon="ERROR")
        if s.enabled:
            live = MANAGER.boards.get(active_object(context).session_uid)
            state = live.state if live is not None else "Waiting for the first render"
            col.label(text=state, icon="ERROR" if state.startswith("Failed") else "INFO")
        denoiser_notice(layout, context)
        row = layout.row()
        row.scale_y = 1.4
        row.operator("tessera.impostor_bake", icon="IMAGE_PLANE")


def denoiser_notice(layout, context):
    """Where this Blender's Cycles has no denoiser: boards and cards keep their grain, and more samples is the cure."""
    if not compat.has_denoiser():
        wrapped_label(layout.box(), context, "This Blender has no denoiser (OpenImageDenoise), so boards and cards "
                      "keep Cycles' grain: raise Samples (64 or more) for smoother ones.", icon="INFO")


classes = (TESSERA_PT_impostors,)
register, unregister = bpy.utils.register_classes_factory(classes)

"""Sidebar › Tessera › Start Here: the panel that keeps the Tessera tab in the sidebar when nothing Tessera works on
is active, with the creators (Add › Tessera), what to select for the other tools, and a link to the manual."""

import bpy

from .manifest import manual_url
from .menus import ADD_MENU, ICONS
from .sidebar import Sidebar, panel_order, wrapped_label
from .viewport import stopped_previews

#: What to select for each of Tessera's tools (shown when nothing fitting is active).
SELECT_HINTS = (
    ("MESH_DATA", "A mesh: Tessellate, Loop Subdivision, Displacement Map, Impostors"),
    ("CURVE_DATA", "A curve, hair or wire mesh (edges only): Tubes"),
    ("SURFACE_DATA", "A NURBS surface: Object › Tessera › Tessellate Surface"),
)


class TESSERA_PT_start(Sidebar, bpy.types.Panel):
    bl_idname = "TESSERA_PT_start"
    bl_order = panel_order(bl_idname)
    bl_label = "Start Here"

    @classmethod
    def poll(cls, context):
        """Shown exactly when no other Tessera sidebar panel is: the tab is always there."""
        return not any(panel.poll(context) for panel in Sidebar.__subclasses__()
                       if panel is not cls and getattr(panel, "is_registered", False))

    def draw(self, context):
        layout = self.layout
        col = layout.column(align=True)
        col.label(text="Add something new:")
        col.operator_context = "INVOKE_REGION_WIN"
        for idname in ADD_MENU:
            col.operator(idname, icon=ICONS[idname])
        layout.label(text="Or select an object to work on:")
        for icon, text in SELECT_HINTS:
            wrapped_label(layout, context, text, icon)
        if manual_url():
            layout.operator("wm.url_open", text="Manual", icon="HELP").url = manual_url()


class TESSERA_PT_gpu_notice(bpy.types.Panel):
    """Shown while a viewport preview has stopped because a shader does not compile on this GPU driver: why, once."""

    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Tessera"
    bl_idname = "TESSERA_PT_gpu_notice"
    bl_order = panel_order(bl_idname)
    bl_label = "Preview Stopped"

    @classmethod
    def poll(cls, context):
        return bool(stopped_previews())

    def draw(self, context):
        col = self.layout.column(align=True)
        for topic, message in stopped_previews().items():
            col.label(text=f"The {topic} preview stopped drawing:", icon="ERROR")
            wrapped_label(col, context, message)
        wrapped_label(col, context, "Operators still work: they compute on the CPU.")


classes = (TESSERA_PT_gpu_notice, TESSERA_PT_start)
register, unregister = bpy.utils.register_classes_factory(classes)

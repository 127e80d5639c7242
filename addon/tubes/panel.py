"""Sidebar panel Tessera > Tubes: the object's tube settings, the preview toggle, and the mesh operator."""

import bpy

from ..settings_scaffold import copy_options
from ..sidebar import Sidebar, active_object, panel_order, preview_notice
from .settings import TubeOptions, draw_tubes_settings
from .sources import SOURCE_TYPES


class TESSERA_PT_tubes(Sidebar, bpy.types.Panel):
    bl_idname = "TESSERA_PT_tubes"
    bl_order = panel_order(bl_idname)
    bl_label = "Tubes"
    object_types = frozenset(SOURCE_TYPES)

    @classmethod
    def poll(cls, context):
        """Curves and hair; of meshes, wire meshes (edges, no faces) or one whose tube preview is on: a mesh with
        faces is not what tubes are made from (*Object › Tessera › Tubes* still takes its edges)."""
        ob = active_object(context)
        if ob is None or ob.type not in cls.object_types:
            return False
        if ob.type != "MESH" or ob.tessera.tubes.preview:
            return True
        return len(ob.data.edges) > 0 and len(ob.data.polygons) == 0
    def draw_header(self, context):
        self.layout.prop(active_object(context).tessera.tubes, "preview", text="")

    def draw(self, context):
        settings = active_object(context).tessera.tubes
        preview_notice(self.layout, context, settings.preview, "make the mesh (Make Tube Mesh) or add the Tessera "
                       "Tubes node group")
        draw_tubes_settings(self.layout, settings)
        row = self.layout.row()
        row.scale_y = 1.4
        op = row.operator("tessera.tubes", icon="MESH_CYLINDER", text="Make Tube Mesh")
        copy_options(TubeOptions, settings, op)


classes = (TESSERA_PT_tubes,)
register, unregister = bpy.utils.register_classes_factory(classes)

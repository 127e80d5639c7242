"""Sidebar panel Tessera > Node Groups: every Tessera geometry-nodes group, one button each to add it as a modifier
to the selected objects (the same groups are in Add Modifier > Tessera through the asset library)."""

import bpy

from . import node_groups, node_library  # noqa: F401 (node_library: every group registered)
from .sidebar import Sidebar, panel_order


class TESSERA_PT_node_groups(Sidebar, bpy.types.Panel):
    bl_idname = "TESSERA_PT_node_groups"
    bl_order = panel_order(bl_idname)
    bl_label = "Node Groups"
    bl_options = {"DEFAULT_CLOSED"}
    object_types = frozenset({"MESH", "CURVES", "CURVE"})

    def draw(self, context):
        col = self.layout.column(align=True)
        for name, spec in sorted(node_groups.GROUPS.items()):
            reason = spec.available() if spec.available is not None else None
            row = col.row(align=True)
            row.enabled = reason is None
            row.operator("tessera.node_group_add", text=name, icon="GEOMETRY_NODES").group = name
            if reason:
                col.label(text=reason, icon="INFO")


classes = (TESSERA_PT_node_groups,)
register, unregister = bpy.utils.register_classes_factory(classes)

"""``tessera.node_group_add``: one of Tessera's geometry-nodes groups as a modifier on the selected objects."""

import bpy

from ..addon import node_groups, node_library  # noqa: F401 (node_library: every group registered)
from ..addon.guarded import guarded
from ..kernels.common.errors import InvalidInputError

_ITEMS = []  # Blender keeps only pointers to the strings of dynamic enum items: they must outlive the call


def _group_items(self, context):
    _ITEMS[:] = [(name, name, f"Add {name} as a modifier") for name in sorted(node_groups.GROUPS)]
    return _ITEMS


class TESSERA_OT_node_group_add(bpy.types.Operator):
    """Add a Tessera node group to the selected objects as a modifier that renders even without the add-on"""

    bl_idname = "tessera.node_group_add"
    bl_label = "Add Tessera Node Group"
    bl_options = {"REGISTER", "UNDO"}

    group: bpy.props.EnumProperty(name="Group", items=_group_items, description="The node group to add")

    @classmethod
    def poll(cls, context):
        if not [ob for ob in context.selected_objects if ob.type in {"MESH", "CURVES", "CURVE"}]:
            cls.poll_message_set("Select the objects to add the group to")
            return False
        return True

    @guarded
    def execute(self, context, tx):
        spec = node_groups.GROUPS.get(self.group)
        if spec is None:
            raise InvalidInputError(f"No Tessera node group is called {self.group!r}")
        reason = spec.available() if spec.available is not None else None
        if reason:
            raise InvalidInputError(reason)
        created = spec.name not in bpy.data.node_groups
        tree = node_groups.ensure_group(spec)
        if created:
            tx.track(tree)
        targets = [ob for ob in context.selected_objects if ob.type in {"MESH", "CURVES", "CURVE"}]
        for ob in targets:
            mod = ob.modifiers.new(spec.name, "NODES")
            mod.node_group = tree
            tx.on_rollback(lambda ob=ob, mod=mod: ob.modifiers.remove(mod))
        self.report({"INFO"}, f"Added {spec.name} to {len(targets)} object(s)")
        return {"FINISHED"}


classes = (TESSERA_OT_node_group_add,)
register, unregister = bpy.utils.register_classes_factory(classes)

"""Geometry-nodes groups built by code: the helper every builder uses, the versioned get-or-build, and the
registry of Tessera's groups (each capability's ``*_nodes`` module adds its own with `register_group`).

A group carries ``tessera_version``: a file holding an older copy gets it rebuilt in place (same data block, so
modifiers that use it follow), never a second copy. Groups meant for the modifier stack are flagged as
modifiers (they show in Add Modifier) and get a description per socket.
"""

from dataclasses import dataclass

import bpy

from .compat import menu_input_value, set_modifier_input, set_socket_subtype


class Graph:
    """Adds nodes and links to a node tree."""

    def __init__(self, tree):
        self.tree = tree

    def node(self, kind, inputs=(), **props):
        n = self.tree.nodes.new(kind)
        for key, value in props.items():
            setattr(n, key, value)
        for i, value in inputs:
            self.feed(n.inputs[i], value)
        return n

    def feed(self, socket, value):
        if isinstance(value, bpy.types.NodeSocket):
            self.tree.links.new(value, socket)
        else:
            socket.default_value = value

    def math(self, op, *args):
        n = self.node("ShaderNodeMath", operation=op)
        for i, a in enumerate(args):
            self.feed(n.inputs[i], a)
        return n.outputs[0]

    def vec(self, op, *args, out=0):
        n = self.node("ShaderNodeVectorMath", operation=op)
        sockets = ("Vector", "Scale") if op == "SCALE" else range(len(args))
        for i, a in zip(sockets, args, strict=True):
            self.feed(n.inputs[i], a)
        return n.outputs[out]

    def xyz(self, x, y, z):
        return self.node("ShaderNodeCombineXYZ", [(0, x), (1, y), (2, z)]).outputs[0]

    def split(self, vector):
        return self.node("ShaderNodeSeparateXYZ", [(0, vector)]).outputs

    def at(self, domain, data_type, value, index):
        """``value`` evaluated on ``domain`` at ``index`` (Evaluate at Index)."""
        return self.node("GeometryNodeFieldAtIndex", [("Value", value), ("Index", index)], domain=domain,
                         data_type=data_type).outputs[0]  # by name: 4.2 has Index first, 5.x Value first

    def store(self, geometry, name, value, data_type="FLOAT", domain="POINT"):
        """``geometry`` with the named attribute ``name`` set to the field ``value``."""
        return self.node("GeometryNodeStoreNamedAttribute", [(0, geometry), ("Name", name), ("Value", value)],
                         data_type=data_type, domain=domain).outputs[0]

    def named(self, name, data_type="FLOAT"):
        return self.node("GeometryNodeInputNamedAttribute", [(0, name)], data_type=data_type).outputs[0]

    def remove(self, geometry, names):
        for name in names:
            geometry = self.node("GeometryNodeRemoveAttribute", [(0, geometry), ("Name", name)]).outputs[0]
        return geometry

    def switch(self, data_type, condition, false, true):
        return self.node("GeometryNodeSwitch", [("Switch", condition), ("False", false), ("True", true)],
                         input_type=data_type).outputs[0]

    def menu(self, data_type, menu, options):
        """A Menu Switch driven by the group input socket ``menu``: ``options`` is ``[(item name, value), ...]``,
        the first item the input's default. Returns the switch's output."""
        node = self.node("GeometryNodeMenuSwitch", data_type=data_type)
        node.enum_items.clear()
        for i, (name, value) in enumerate(options):
            node.enum_items.new(name)
            self.feed(node.inputs[i + 1], value)
        self.tree.links.new(menu, node.inputs[0])
        self.tree.interface.items_tree[menu.name].default_value = options[0][0]  # items known once linked
        return node.outputs[0]

    def input(self, kind, output=0):
        """The output ``output`` of a new input node (Position, Index, ...)."""
        return self.node(kind).outputs[output]

    def on(self, domain, data_type, value):
        """``value`` evaluated on ``domain`` and read back in the caller's domain (Evaluate on Domain)."""
        return self.node("GeometryNodeFieldOnDomain", [("Value", value)], domain=domain,
                         data_type=data_type).outputs[0]


def socket(tree, name, kind, in_out="INPUT", description="", default=None, min_value=None, max_value=None,
           subtype=None):
    """An interface socket with its tooltip, default, range and ``subtype`` (DISTANCE, ANGLE, FACTOR, PIXEL ...: the
    unit the modifier panel shows)."""
    item = tree.interface.new_socket(name, in_out=in_out, socket_type=kind)
    item.description = description
    if subtype is not None:
        set_socket_subtype(item, subtype)
    if default is not None:
        item.default_value = default
    if min_value is not None:
        item.min_value = min_value
    if max_value is not None:
        item.max_value = max_value
    return item


@dataclass(frozen=True)
class GroupSpec:
    """A Tessera group: its name, graph version, builder ``build(tree)``, one-sentence ``description`` (the group's
    tooltip and its asset description), catalog path and whether it is a modifier (shown in Add Modifier)."""

    name: str
    version: int
    build: object
    description: str
    catalog: str = "Tessera"
    modifier: bool = True
    available: object = None  # callable -> None or the reason this Blender cannot build it


GROUPS = {}


def register_group(spec):
    GROUPS[spec.name] = spec
    return spec


def ensure_group(spec):
    """The group in this file, built on first use and rebuilt when its version is older."""
    tree = bpy.data.node_groups.get(spec.name)
    if tree is not None and tree.get("tessera_version") == spec.version:
        return tree
    if tree is not None:
        tree.nodes.clear()
        tree.interface.clear()
    else:
        tree = bpy.data.node_groups.new(spec.name, "GeometryNodeTree")
    spec.build(tree)
    tree.description = spec.description
    if spec.modifier and hasattr(tree, "is_modifier"):
        tree.is_modifier = True
    tree["tessera_version"] = spec.version
    return tree


def set_inputs(mod, values):
    """Set a Nodes modifier's group inputs from ``{socket name: value}`` and tag its object for re-evaluation
    (input values are ID properties: changing them does not tag the depsgraph by itself)."""
    for item in mod.node_group.interface.items_tree:
        if item.item_type == "SOCKET" and item.in_out == "INPUT" and item.name in values:
            value = values[item.name]
            if item.socket_type == "NodeSocketMenu":  # by the item's name
                value = menu_input_value(mod.node_group, item, value)
            set_modifier_input(mod, item.identifier, value)
    mod.id_data.update_tag()

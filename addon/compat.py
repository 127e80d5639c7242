"""What differs between the supported Blenders (4.2 LTS, 4.5 LTS, 5.0, 5.1, 5.2), in one place.

Everything else calls these instead of testing ``bpy.app.version``; a feature is detected where Blender lets us
ask for it, and the version is compared only where the difference cannot be seen any other way.

- custom normals: 5.0+ keeps them as a float ``custom_normal`` attribute (exact); before, as two 16-bit angles in
  each corner fan's normal space, set through ``normals_split_custom_set`` (`FLOAT_CUSTOM_NORMALS`,
  `set_split_custom_normals`, `CUSTOM_NORMAL_STORAGE_ERROR`);
- stroke elements: 4.2's `OperatorStrokeElement` requires ``pen_flip`` when built from Python (`stroke_element`);
- geometry-nodes modifier inputs: ``mod[identifier] = value`` until 5.1, ``mod.properties.inputs`` from 5.2
  (`set_modifier_input`); menu inputs by item name from 5.2, by an internal integer before (`menu_input_value`);
- the Normal geometry node gives corner normals on the corner domain from 4.5, face normals on 4.2
  (`NORMAL_NODE_CORNER_NORMALS`);
- geometry nodes write custom normals (Set Mesh Normal) from 4.5 (`has_set_mesh_normal_node`);
- the UV Tangent geometry node exists from 5.0 (`has_uv_tangent_node`, `UV_TANGENT_MESSAGE`);
- materials: 5.0+ materials always have a node tree (``use_nodes`` is deprecated); 4.x needs the flag set
  (`use_material_nodes`);
- geometry-node modes (Set Curve Normal, Resample Curve, Merge by Distance, ...): a node property until 4.5, a
  menu input socket from 5.0 (`set_node_mode`); Curve to Mesh scales the profile by the curve radius by itself in
  4.2 and through its Scale input from 4.5 (builders link the radius where the node has that input);
- a worker's render reports its samples through the ``render_stats`` handler from 5.2; on 4.2 the handler crashed
  the worker's background render (`RENDER_STATS_IN_WORKERS`: before, progress moves per view only);
- the memory layout behind RNA items (face offsets, attribute values) is the same in all of them; `mesh_memory`
  checks it at run time instead of assuming it. The face offsets are closed by the corner count in all of them
  (`FACE_OFFSETS_CLOSED`).
"""

import math

import bpy

#: A worker's background render may report its samples through ``bpy.app.handlers.render_stats`` (5.2; on 4.2 the
#: handler crashed the worker, exit -11, as the first statistics came in).
RENDER_STATS_IN_WORKERS = bpy.app.version >= (5, 2, 0)

#: 5.0+ stores custom normals as a float vector attribute (what is written is what is read back).
FLOAT_CUSTOM_NORMALS = bpy.app.version >= (5, 0, 0)

#: Largest change, per component, that storing a unit custom normal makes. None in 5.0+. Before 5.0 a corner
#: normal is kept as two 16-bit angles in its fan's normal space: the angle from the fan's reference normal comes
#: from ``acosf``, whose resolution near 1 is sqrt(2 * 2^-24) ≈ 3.45e-4 rad, and the two angles are rounded to
#: half a step of π/32767 and 2π/32767. Measured: 3.3e-4 on Suzanne (4.2.23, 4.5.15). Tests add it to their own
#: tolerance for every stored normal they compare, so the 5.x tolerances stay what they were.
CUSTOM_NORMAL_STORAGE_ERROR = 0.0 if FLOAT_CUSTOM_NORMALS else math.sqrt(2.0 * 2.0 ** -24) + 3.0 * math.pi / 65534

#: The Normal geometry node gives Blender's corner normals (sharp edges, flat faces, custom normals) on the face
#: corner domain in 4.5 and later (4.2: the face normal; 4.3 and 4.4 are not supported, so not
#: checked). Nothing to ask Blender: the node is the same, only what it computes differs.
NORMAL_NODE_CORNER_NORMALS = bpy.app.version >= (4, 5, 0)

#: A mesh's face offsets are one array of F + 1 ints: each face's first corner, then the corner count (Blender
#: 3.6 and later, so every supported one). A writer that fills them in place checks the last face's size afterwards.
FACE_OFFSETS_CLOSED = bpy.app.version >= (3, 6, 0)

UV_TANGENT_MESSAGE = "Tangent-space maps need Blender 5.0 or newer (its UV Tangent node)"


def set_split_custom_normals(mesh, normals, domain="CORNER"):
    """Before 5.0: corner (L, 3) or point (V, 3) float32 unit normals as ``mesh``'s custom normals (Blender
    encodes them; see `CUSTOM_NORMAL_STORAGE_ERROR`). 5.0+ writes the ``custom_normal`` attribute instead."""
    if domain == "POINT":
        mesh.normals_split_custom_set_from_vertices(normals)
    else:
        mesh.normals_split_custom_set(normals)


def stroke_element(location, pressure=1.0, first=False, mouse=(0.0, 0.0)):
    """One element of a paint stroke (the ``stroke`` collection of a stroke operator) as a dict holding every
    field this Blender's `OperatorStrokeElement` has (4.2 refuses a dict without ``pen_flip``)."""
    element = {"name": "", "location": tuple(location), "mouse": tuple(mouse), "mouse_event": tuple(mouse),
               "pressure": float(pressure), "size": 0.0, "x_tilt": 0.0, "y_tilt": 0.0, "time": 0.0,
               "is_start": bool(first), "pen_flip": False}
    known = set(bpy.types.OperatorStrokeElement.bl_rna.properties.keys())
    return {key: value for key, value in element.items() if key in known}


def _inputs(mod):
    """5.2+: the struct whose attributes are the modifier's inputs by identifier; None before."""
    props = getattr(mod, "properties", None)
    return getattr(props, "inputs", None)


def set_modifier_input(mod, identifier, value):
    """Set a geometry-nodes modifier's group input ``identifier`` (e.g. ``"Socket_2"``) to ``value``."""
    inputs = _inputs(mod)
    if inputs is None:
        mod[identifier] = value
    else:
        getattr(inputs, identifier).value = value


def set_node_mode(node, name, identifier, label):
    """Choose a geometry node's mode: the input socket ``name`` (5.0+, the item's ``label``) where the node has
    one, else the property ``name.lower()`` (the item's ``identifier``)."""
    socket = node.inputs.get(name)
    if socket is not None and socket.type == "MENU":
        socket.default_value = label
    else:
        setattr(node, name.lower().replace(" ", "_"), identifier)



def menu_input_value(tree, item, label):
    """What `set_modifier_input` takes for the menu socket ``item`` of ``tree`` set to its item ``label``: the label
    from 5.2 (``mod.properties.inputs`` speaks names); before, the item's internal integer identifier, which Python
    cannot read: a throw-away modifier on a throw-away mesh is made with the label as the socket's default and
    its stored value is read back."""
    if hasattr(bpy.types, "NodesModifier") and "properties" in bpy.types.NodesModifier.bl_rna.properties:
        return label
    old = item.default_value
    mesh = bpy.data.meshes.new("__tessera_menu_probe")
    probe = bpy.data.objects.new("__tessera_menu_probe", mesh)
    try:
        item.default_value = label
        mod = probe.modifiers.new("probe", "NODES")
        mod.node_group = tree
        return int(mod[item.identifier])
    finally:
        bpy.data.objects.remove(probe)
        bpy.data.meshes.remove(mesh)
        item.default_value = old


def has_denoiser():
    """True when this Blender's Cycles has OpenImageDenoise (official builds do; some distributions' builds do not):
    without it Cycles renders keep their grain whatever the scene's denoising setting."""
    try:
        import _cycles
    except ImportError:
        return False
    return bool(getattr(_cycles, "with_openimagedenoise", False))


def has_uv_tangent_node():
    """True when this Blender has the UV Tangent geometry node (5.0 and newer)."""
    return hasattr(bpy.types, "GeometryNodeUVTangent")


def has_set_mesh_normal_node():
    """True when geometry nodes can write custom normals (the Set Mesh Normal node, 4.5 and newer)."""
    return hasattr(bpy.types, "GeometryNodeSetMeshNormal")


def use_material_nodes(material):
    """Make ``material`` a node material (4.x: ``use_nodes``, which adds the default Principled BSDF; 5.0+ always
    has its node tree and deprecates the flag)."""
    if material.node_tree is None:
        material.use_nodes = True


def set_socket_subtype(item, subtype):
    """Give a group interface socket ``item`` a subtype (DISTANCE, ANGLE, FACTOR, PIXEL ...) where this Blender has
    it for that socket type (4.2 has no PIXEL sockets); elsewhere it keeps its plain number display."""
    try:
        item.subtype = subtype
    except TypeError:
        pass

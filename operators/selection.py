"""What a mesh operator reads and leaves: the source mesh (the evaluated object for a new object, its own mesh for
Replace), the result placed beside the source or swapped into it, and the results selected, the last one active."""

import bpy

from ..addon import bridge
from ..addon.guarded import check_editable


def select_only(context, objects):
    """Deselect everything, select ``objects`` and make the last of them active (if any)."""
    for other in context.selected_objects:
        other.select_set(False)
    for ob in objects:
        ob.select_set(True)
    if objects:
        context.view_layer.objects.active = objects[-1]


def is_mesh(ob):
    """``ob`` is a mesh object (what the mesh operators act on, each selected one: `guarded.each_selected`)."""
    return ob.type == "MESH"


def mesh_poll(cls, context, verb):
    """Poll of an operator on the active mesh in Object Mode; says why not (``verb``: what the operator does)."""
    ob = context.active_object
    if ob is None or ob.type != "MESH":
        cls.poll_message_set(f"Select a mesh object to {verb} (make it active)")
        return False
    if context.mode != "OBJECT":
        cls.poll_message_set(f"Switch to Object Mode to {verb}")
        return False
    return True


def object_poll(cls, context, types, message):
    """Poll of an operator on the active object of one of ``types`` (object type names) in Object Mode; when not,
    sets ``message`` as the reason."""
    ob = context.active_object
    if context.mode != "OBJECT" or ob is None or ob.type not in types:
        cls.poll_message_set(message)
        return False
    return True


def read_source(context, ob, output):
    """`bridge.read_mesh` of what the operator works on: the object with its modifiers evaluated for a new
    object, its own mesh data for ``output == "REPLACE"``. Returns ``(arrays, info, marks)`` (marks:
    `bridge.read_edge_marks`)."""
    if output == "REPLACE":
        check_editable(ob, "its mesh", "Choose Output: New Object, or make it local (Object › Relations › Make "
                                       "Local)")
    if output == "NEW_OBJECT":
        evaluated = ob.evaluated_get(context.evaluated_depsgraph_get())
        source = evaluated.to_mesh()
    else:
        evaluated, source = None, ob.data
    try:
        arrays, info = bridge.read_mesh(source)
        marks = bridge.read_edge_marks(source)
    finally:
        if evaluated is not None:
            evaluated.to_mesh_clear()
    return arrays, info, marks


#: The operator option that hides the source under a new object made exactly over it (Tessellate, Loop Subdivide).
HIDE_SOURCE = bpy.props.BoolProperty(
    name="Hide Source", default=True,
    description="Hide the source object in the viewport and in renders, so the new object over it shows alone (the "
                "eye and camera icons in the Outliner bring it back)")


def place_mesh(context, tx, ob, mesh, output, suffix, hide_source=False):
    """Put ``mesh`` (mesh or curve data, as ``ob``'s) in the scene: swapped into ``ob`` (REPLACE; the old mesh
    removed if nothing else uses it, undone on rollback) or as a new object ``<ob.name>.<suffix>`` in ``ob``'s
    collections with its transform and object-linked materials, selected and active, ``ob`` hidden in the viewport
    and in renders when ``hide_source`` (both undone on rollback). Returns the object that holds it."""
    for material in ob.data.materials:
        mesh.materials.append(material)
    if output == "REPLACE":
        old = ob.data
        ob.data = mesh
        tx.on_rollback(lambda: setattr(ob, "data", old))
        if old.users == 0:
            old_name = old.name
            bpy.data.meshes.remove(old)
            mesh.name = old_name
        return ob
    new = tx.new_object(f"{ob.name}.{suffix}", mesh)
    for collection in ob.users_collection:
        collection.objects.link(new)
    new.matrix_world = ob.matrix_world.copy()
    for src_slot, dst_slot in zip(ob.material_slots, new.material_slots, strict=False):
        if src_slot.link == "OBJECT":
            dst_slot.link = "OBJECT"
            dst_slot.material = src_slot.material
    if hide_source:
        view_layer, hidden, unrendered = context.view_layer, ob.hide_get(view_layer=context.view_layer), ob.hide_render

        def show_again():
            ob.hide_set(hidden, view_layer=view_layer)
            ob.hide_render = unrendered

        ob.hide_set(True, view_layer=view_layer)
        ob.hide_render = True
        tx.on_rollback(show_again)
    select_only(context, [new])
    return new

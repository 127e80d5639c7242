"""A baked impostor card written to glTF (binary .glb) through Blender's own exporter.

glTF cannot carry the card's view selection (a shader graph), so the file holds what an engine needs to draw the
impostor itself, and a picture for viewers that know nothing of impostors:
- the card (a quad as large as the object's bounding sphere, at its centre) with an unlit material
  (``KHR_materials_unlit``, alpha blended) whose base colour is the colour atlas, the card's UVs mapped to one view
  (the one looking along +y, the object's front: `FALLBACK_DIRECTION`), so any viewer shows a picture of the object;
- the whole atlas as that image, and the node's extras ``tessera_impostor``: layout ("octahedral" or
  "hemi-octahedral", `kernels.impostors.octahedral`), grid (views a side), the fallback view's cell, size, blend:
  what an engine's impostor shader needs to pick (or blend) the view of each direction.
The card is written from a temporary copy (its own mesh, material and object), removed again whatever happens; the
file is written next to its destination and moved into place once whole.
"""

import errno
import os
import tempfile

import addon_utils
import bpy
import numpy as np

from ...kernels.common import written
from ...kernels.common.errors import InvalidInputError, TesseraError
from ...kernels.impostors.octahedral import cell_of
from ..node_groups import Graph

#: The view a viewer without an impostor shader shows: looking along +y (Blender's front view).
FALLBACK_DIRECTION = np.array([0.0, -1.0, 0.0])
#: The custom property a baked card carries (`bake.make_card`).
PROPERTY = "tessera_impostor"


def impostor_info(ob):
    """The bake's record on a card (a dict: grid, hemi, size, blend), or None for any other object."""
    info = ob.get(PROPERTY) if ob is not None else None
    return None if info is None else info.to_dict()


def export_card(card, filepath):
    """Write ``card`` (a baked impostor card) to ``filepath`` (.glb). Raises `InvalidInputError` for another object
    or a card without its atlas, `TesseraError` when the exporter fails; nothing is left behind either way."""
    info = impostor_info(card)
    if info is None:
        raise InvalidInputError(f"{card.name!r} is not an impostor card (bake one with Bake Impostor)")
    image = _atlas_image(card)
    folder = os.path.dirname(os.path.abspath(filepath))
    if not os.path.isdir(folder):
        raise InvalidInputError(f"The folder {folder!r} does not exist")
    _ensure_exporter()
    grid, hemi = int(info["grid"]), bool(info["hemi"])
    cell = cell_of(FALLBACK_DIRECTION, grid, hemi)
    extras = {**info, "layout": "hemi-octahedral" if hemi else "octahedral", "fallback_view": [int(c) for c in cell],
              "atlas": image.name}
    made, selection = [], (list(bpy.context.selected_objects), bpy.context.view_layer.objects.active)
    try:
        handle, part = tempfile.mkstemp(suffix=".glb", dir=folder)
    except OSError as err:
        raise TesseraError(f"{filepath}: not written: {written.os_cause(err)}") from None
    os.close(handle)
    try:
        ob = _export_copy(card, image, grid, cell, extras, made)
        for other in bpy.context.selected_objects:
            other.select_set(False)
        ob.select_set(True)
        bpy.context.view_layer.objects.active = ob
        try:
            result = bpy.ops.export_scene.gltf(filepath=part, export_format="GLB", use_selection=True,
                                               export_extras=True)
        except RuntimeError as err:  # the exporter's exception: the cause when it is the disk's
            cause = written.cause_in_text(str(err))
            if cause is None:
                raise
            raise TesseraError(f"{filepath}: not written: {cause}") from None
        if result != {"FINISHED"} or os.path.getsize(part) == 0:
            raise TesseraError(f"Blender's glTF exporter did not write {filepath!r}")
        try:
            written.check_written(part)  # the exporter says nothing of a short write (a full disk)
        except written.ShortWrite as err:
            cause = written.CAUSES[errno.ENOSPC] if written.disk_full(folder) else str(err)
            raise TesseraError(f"{filepath}: not written: {cause}") from None
        os.replace(part, filepath)
    finally:
        if os.path.exists(part):
            os.remove(part)
        for block, collection in reversed(made):
            collection.remove(block)
        for other in selection[0]:
            if other.name in bpy.data.objects:
                other.select_set(True)
        bpy.context.view_layer.objects.active = selection[1]


def _atlas_image(card):
    material = card.active_material
    nodes = material.node_tree.nodes if material is not None and material.node_tree is not None else ()
    for node in nodes:
        if node.type == "TEX_IMAGE" and node.image is not None:
            return node.image
    raise InvalidInputError(f"{card.name!r} has lost its atlas image (its material has no image texture)")


def _export_copy(card, image, grid, cell, extras, made):
    """A temporary object to export: the card's quad, its UVs mapped into the fallback view's cell, an unlit
    material in the form the exporter reads as ``KHR_materials_unlit`` with alpha, the extras."""
    me = card.data.copy()
    made.append((me, bpy.data.meshes))
    uv = me.uv_layers.active.data
    coords = np.empty(2 * len(uv), np.float32)
    uv.foreach_get("uv", coords)
    coords = (coords.reshape(-1, 2) + np.asarray(cell, np.float32)) / grid
    uv.foreach_set("uv", coords.ravel())
    mat = bpy.data.materials.new(f"{card.name} glTF")
    made.append((mat, bpy.data.materials))
    if mat.node_tree is None:
        mat.use_nodes = True
    tree = mat.node_tree
    tree.nodes.clear()
    g = Graph(tree)
    tex = g.node("ShaderNodeTexImage", image=image, interpolation="Linear", extension="EXTEND")
    emit = g.node("ShaderNodeEmission", [("Color", tex.outputs["Color"]), ("Strength", 1.0)])
    camera_only = g.node("ShaderNodeMixShader", [(0, g.node("ShaderNodeLightPath").outputs["Is Camera Ray"]),
                                                 (1, g.node("ShaderNodeBsdfTransparent").outputs[0]),
                                                 (2, emit.outputs[0])])
    alpha = g.node("ShaderNodeMixShader", [(0, tex.outputs["Alpha"]),
                                           (1, g.node("ShaderNodeBsdfTransparent").outputs[0]),
                                           (2, camera_only.outputs[0])])
    tree.links.new(alpha.outputs[0], g.node("ShaderNodeOutputMaterial").inputs["Surface"])
    me.materials.clear()
    me.materials.append(mat)
    ob = bpy.data.objects.new(f"{card.name} (glTF)", me)
    made.append((ob, bpy.data.objects))
    ob.location = card.matrix_world.translation
    ob[PROPERTY] = extras
    bpy.context.scene.collection.objects.link(ob)
    return ob


def _ensure_exporter():
    if not hasattr(bpy.ops.export_scene, "gltf"):
        addon_utils.enable("io_scene_gltf2", default_set=False)
    if not hasattr(bpy.ops.export_scene, "gltf"):
        raise TesseraError("Blender's glTF exporter (io_scene_gltf2) is not available in this Blender")

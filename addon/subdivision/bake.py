"""Baking the light on a mesh's sub-triangles with Cycles (for the HCE): a temporary copy of the subdivided mesh
with one atlas cell per sub-triangle, Blender's own bake (diffuse, direct + indirect), the mean of each cell.

Nothing of the user's is changed: the copy, its material copies and the image are removed afterwards, and the
render engine, samples, bake settings, selection and the source's render visibility are put back, also when the
bake fails.
"""

from contextlib import contextmanager

import bpy
import numpy as np

from ...kernels.common.errors import TesseraError
from ...kernels.common.mesh_arrays import MeshArrays
from ...kernels.subdivision.bake_atlas import atlas_size, atlas_uvs, triangle_means
from .. import bridge, compat
from ..guarded import remove_block

UV_NAME = "TesseraBake"


@contextmanager
def _restored(scene, ob):
    """Put back what the bake changes on the scene and the source object."""
    cycles = scene.cycles
    saved = (scene.render.engine, cycles.samples, cycles.device, scene.render.bake.margin,
             scene.render.bake.use_clear, scene.render.bake.target, ob.hide_render)
    view_layer = bpy.context.view_layer
    selected = [o for o in view_layer.objects if o.select_get()]
    active = view_layer.objects.active
    try:
        yield
    finally:
        (scene.render.engine, cycles.samples, cycles.device, scene.render.bake.margin,
         scene.render.bake.use_clear, scene.render.bake.target, ob.hide_render) = saved
        for o in view_layer.objects:
            o.select_set(o in selected)
        view_layer.objects.active = active


def _bake_material(source, image):
    """A copy of ``source`` (or a plain white material) whose active node is an image node on ``image``."""
    mat = source.copy() if source is not None else bpy.data.materials.new("TesseraBake")
    compat.use_material_nodes(mat)
    node = mat.node_tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    mat.node_tree.nodes.active = node
    return mat


def bake_colours(context, ob, positions, triangles, material_index, samples, albedo):
    """Lit colour (N, 4) float32 of each triangle of ``positions`` (V, 3) / ``triangles`` (N, 3) in ``ob``'s
    space, as Cycles bakes it in ``ob``'s place (``ob`` itself hidden from the render meanwhile).

    material_index: (N,) int slot of each triangle in ``ob``'s materials. albedo: include the surface colour
    (else the light alone). Raises `TesseraError` when Blender's bake fails.
    """
    scene = context.scene
    n = len(triangles)
    _, res = atlas_size(n)
    arrays = MeshArrays(positions=np.asarray(positions, np.float32), triangles=np.asarray(triangles, np.int32),
                        corner_attributes={UV_NAME: atlas_uvs(n)},
                        face_attributes={"material_index": np.asarray(material_index, np.int32)},
                        attribute_types={UV_NAME: "FLOAT2", "material_index": "INT"})
    made = []
    try:
        mesh = bridge.write_mesh("TesseraBake", arrays)
        made.append(mesh)
        mesh.uv_layers.active = mesh.uv_layers[UV_NAME]
        image = bpy.data.images.new("TesseraBake", res, res, alpha=True, float_buffer=True)
        made.append(image)
        for slot in ob.material_slots or [None]:
            mat = _bake_material(slot.material if slot is not None else None, image)
            made.append(mat)
            mesh.materials.append(mat)
        temp = bpy.data.objects.new("TesseraBake", mesh)
        made.insert(0, temp)
        scene.collection.objects.link(temp)
        temp.matrix_world = ob.matrix_world.copy()
        with _restored(scene, ob):
            scene.render.engine = "CYCLES"
            scene.cycles.samples = int(samples)  # the device stays the user's (GPU where the scene renders on it)
            scene.render.bake.margin = 0
            scene.render.bake.use_clear = True
            scene.render.bake.target = "IMAGE_TEXTURES"
            ob.hide_render = True
            for o in context.view_layer.objects:
                o.select_set(o is temp)
            context.view_layer.objects.active = temp
            passes = {"DIRECT", "INDIRECT"} | ({"COLOR"} if albedo else set())
            try:
                result = bpy.ops.object.bake(type="DIFFUSE", pass_filter=passes, margin=0, use_clear=True)
            except RuntimeError as err:
                raise TesseraError(f"Cycles could not bake the lighting: {err}") from err
            if result != {"FINISHED"}:
                raise TesseraError(f"Cycles could not bake the lighting ({result})")
        pixels = np.empty(res * res * 4, np.float32)
        image.pixels.foreach_get(pixels)
        colours = triangle_means(pixels.reshape(res, res, 4), n)
        colours[:, 3] = 1.0
        return colours
    finally:
        for block in made:
            remove_block(block)

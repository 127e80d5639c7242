"""Baking the light on a mesh's sub-triangles with Cycles (for the HCE), in a worker process (`render_jobs`): a
temporary copy of the subdivided mesh with one atlas cell per sub-triangle, Blender's own bake (diffuse, direct +
indirect) of the scene around it, the mean of each cell.

`start_bake` writes the scene (``bpy.data.libraries.write`` of the scene block: its objects, lights, world and render
settings, the copy in the source's place and the source hidden from the render) into the job's folder and starts
`bake_worker_script.py` on it; the user's file keeps nothing of the bake: the copy, its material copies and the image
are removed again at once, and the source's render visibility is put back. The worker bakes on the user's Cycles device
and writes the image's pixels as a .npy (no colour management between the bake and the means); `read_bake` takes the
cell means and removes the folder. `bake_colours` does all three, waiting, for scripts and ``blender -b``.
"""

import json
import os
from dataclasses import dataclass
from pathlib import Path

import bpy
import numpy as np

from ...kernels.common.budget import check_bytes
from ...kernels.common.errors import TesseraError
from ...kernels.common.mesh_arrays import MeshArrays
from ...kernels.subdivision.bake_atlas import atlas_size, atlas_uvs, triangle_means
from .. import bridge, compat, render_jobs
from ..guarded import remove_block

UV_NAME = "TesseraBake"
SCRIPT = Path(__file__).with_name("bake_worker_script.py")


@dataclass
class BakeJob:
    """A light bake in a worker: the `render_jobs.RenderJob` (one step), the atlas ``res``olution, ``n`` triangles."""

    job: object
    res: int
    n: int
    out: str


def _bake_material(source, image):
    """A copy of ``source`` (or a plain white material) whose active node is an image node on ``image``."""
    mat = source.copy() if source is not None else bpy.data.materials.new("TesseraBake")
    compat.use_material_nodes(mat)
    node = mat.node_tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    mat.node_tree.nodes.active = node
    return mat


def bake_bytes(n):
    """Memory the bake of ``n`` triangles needs at once (the float image in the worker, its pixels here): int."""
    _, res = atlas_size(n)
    return 3 * res * res * 4 * 4


def start_bake(context, ob, positions, triangles, material_index, samples, albedo, budget_bytes, device=None):
    """Start baking the lit colour of each triangle of ``positions`` (V, 3) / ``triangles`` (N, 3) in ``ob``'s space,
    as Cycles sees it in ``ob``'s place (``ob`` hidden from that render): a `BakeJob`, at once.

    material_index: (N,) int slot of each triangle in ``ob``'s materials. albedo: include the surface colour (else the
    light alone). device: the Cycles device (`render_jobs.render_device`; default: the user's)."""
    scene = context.scene
    n = len(triangles)
    check_bytes(bake_bytes(n), budget_bytes, f"Baking the light of {n:,} triangles", "a lower Depth")
    _, res = atlas_size(n)
    arrays = MeshArrays(positions=np.asarray(positions, np.float32), triangles=np.asarray(triangles, np.int32),
                        corner_attributes={UV_NAME: atlas_uvs(n)},
                        face_attributes={"material_index": np.asarray(material_index, np.int32)},
                        attribute_types={UV_NAME: "FLOAT2", "material_index": "INT"})
    folder = render_jobs.job_folder("bake")
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
        blend = os.path.join(folder, "scene.blend")
        hidden = ob.hide_render
        ob.hide_render = True
        try:
            bpy.data.libraries.write(blend, {scene}, path_remap="ABSOLUTE", fake_user=True)
        finally:
            ob.hide_render = hidden
        out = os.path.join(folder, "colours.npy")
        passes = ["DIRECT", "INDIRECT"] + (["COLOR"] if albedo else [])
        job = {"blend": blend, "scene": scene.name, "object": temp.name, "image": image.name, "samples": int(samples),
               "passes": passes, "out": out, "device": device if device is not None else render_jobs.render_device()}
        job_file = os.path.join(folder, "job.json")
        with open(job_file, "w", encoding="utf-8") as f:
            json.dump(job, f)
        log = os.path.join(folder, "worker.log")
        process = render_jobs.start_worker(SCRIPT, job_file, log)
    except BaseException:
        render_jobs.remove_folder(folder)
        raise
    finally:
        for block in made:
            remove_block(block)
    return BakeJob(render_jobs.RenderJob(process, folder, 1, log), res, n, out)


def read_bake(bj):
    """Lit colour (N, 4) float32 (alpha 1) of each triangle of a finished `BakeJob`; the job's folder is removed,
    read or failed. Raises `TesseraError` when Cycles could not bake."""
    try:
        bj.job.check("Baking the lighting")
        if not os.path.isfile(bj.out):
            raise TesseraError("Cycles could not bake the lighting: " + bj.job.tail())
        pixels = np.load(bj.out)
    finally:
        bj.job.close()
    colours = triangle_means(pixels.reshape(bj.res, bj.res, 4), bj.n)
    colours[:, 3] = 1.0
    return colours

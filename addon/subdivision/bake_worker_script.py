"""Run by a separate Blender process (never imported by the add-on): bake the diffuse light on one object's image with
Cycles, in the scene it was written with, and save the image's pixels.

Argument after ``--``: a job file written by `bake.start_bake` (JSON): the blend file holding the scene (the object to
bake in the source's place, the source hidden from the render), the scene's and the object's names, the image's name,
samples, the bake's passes, the Cycles device and where to write the pixels (a .npy of the image's float RGBA, written
under a temporary name and moved into place once whole).
"""

import json
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # addon/: the shared worker module
from worker_device import use_device  # noqa: E402


def main(argv):
    with open(argv[0], encoding="utf-8") as f:
        job = json.load(f)
    bpy.ops.wm.open_mainfile(filepath=job["blend"])
    scene = bpy.data.scenes[job["scene"]]
    ob = bpy.data.objects[job["object"]]
    scene.render.engine = "CYCLES"
    use_device(scene, job.get("device"))
    scene.cycles.samples = int(job["samples"])
    bake = scene.render.bake
    bake.margin, bake.use_clear, bake.target = 0, True, "IMAGE_TEXTURES"
    layer = scene.view_layers[0]
    with bpy.context.temp_override(scene=scene, view_layer=layer, active_object=ob, object=ob,
                                   selected_objects=[ob], selected_editable_objects=[ob]):
        for o in layer.objects:
            o.select_set(o is ob)
        layer.objects.active = ob
        print("TESSERA_PROGRESS 0/1", flush=True)
        result = bpy.ops.object.bake(type="DIFFUSE", pass_filter=set(job["passes"]), margin=0, use_clear=True)
    if result != {"FINISHED"}:
        raise SystemExit(f"Cycles could not bake the lighting ({result})")
    image = bpy.data.images[job["image"]]
    w, h = image.size
    pixels = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(pixels)
    part = job["out"] + ".part.npy"
    np.save(part, pixels)
    os.replace(part, job["out"])
    print("TESSERA_PROGRESS 1/1", flush=True)


main(sys.argv[sys.argv.index("--") + 1:])

"""Run by a separate Blender process (never imported by the add-on): render one object alone with Cycles through
orthographic cameras into multilayer EXRs with their Combined, Depth and Normal passes.

Argument after ``--``: a job file written by `worker.write_job` (JSON): the blend file holding the object, the
lights and the world (and only what they depend on), their names, every object's world matrix, resolution,
samples, orthographic scale, clip end, the views (location, forward, up, out), rendered one after the other (one
for a live board, a grid of them for an impostor atlas); a view may ask for a quick preview render first (progressive
delivery: the viewport draws it until the full render is there), and whether to report the render's samples (where the
Blender allows it: `compat.RENDER_STATS_IN_WORKERS`). The objects are placed in a scene of their own at the matrices
given, unparented and unconstrained, so the render sees them where the viewport does.
"""

import json
import os
import sys

import bpy
from mathutils import Matrix, Vector

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # addon/: the shared worker module
from worker_device import report_samples, use_device  # noqa: E402


def setup(job):
    if bpy.data.filepath != job["blend"]:
        bpy.ops.wm.open_mainfile(filepath=job["blend"])
    scene = bpy.data.scenes.new("tessera_board")
    for name in (job["object"], *job["lights"]):
        ob = bpy.data.objects[name]
        scene.collection.objects.link(ob)
        ob.parent = None
        ob.constraints.clear()
        ob.matrix_world = Matrix(job["matrices"][name])
    if job["world"] is not None:
        scene.world = bpy.data.worlds[job["world"]]
    scene.render.engine = "CYCLES"
    use_device(scene, job.get("device"))
    scene.cycles.samples = int(job["samples"])
    scene.render.resolution_x = scene.render.resolution_y = int(job["resolution"])
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = True
    layer = scene.view_layers[0]
    layer.use_pass_z = layer.use_pass_normal = True
    settings = scene.render.image_settings
    if hasattr(settings, "media_type"):  # 5.0+: multilayer images are a media type of their own
        settings.media_type = "MULTI_LAYER_IMAGE"
    settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = "32"
    return scene


def render_view(scene, loc, fwd, up, scale, clip, out, preview=None):
    """Render one view into ``out``; with ``preview`` (``{"samples", "out"}``) first a quicker render at those
    samples, moved into place under its name only once written whole (the viewport may read it while this goes on)."""
    cam_data = bpy.data.cameras.new("tessera_board_camera")
    cam_data.type, cam_data.ortho_scale, cam_data.clip_start, cam_data.clip_end = "ORTHO", scale, 1e-4, clip
    cam = bpy.data.objects.new("tessera_board_camera", cam_data)
    scene.collection.objects.link(cam)
    loc, fwd, up = Vector(loc), Vector(fwd), Vector(up)
    right = fwd.cross(up).normalized()
    cam.matrix_world = Matrix((
        (right.x, up.x, -fwd.x, loc.x), (right.y, up.y, -fwd.y, loc.y), (right.z, up.z, -fwd.z, loc.z), (0, 0, 0, 1)))
    scene.camera = cam
    if preview is not None:
        samples = scene.cycles.samples
        scene.cycles.samples = int(preview["samples"])
        part = preview["out"] + ".part.exr"
        scene.render.filepath = part
        bpy.ops.render.render(write_still=True, scene=scene.name)
        os.replace(part, preview["out"])
        scene.cycles.samples = samples
    scene.render.filepath = out
    bpy.ops.render.render(write_still=True, scene=scene.name)
    bpy.data.objects.remove(cam)
    bpy.data.cameras.remove(cam_data)


def main(argv):
    with open(argv[0], encoding="utf-8") as f:
        job = json.load(f)
    scene = setup(job)
    if job.get("report_samples"):
        report_samples()
    for k, view in enumerate(job["views"], 1):
        render_view(scene, view["location"], view["forward"], view["up"], job["scale"], job["clip"], view["out"],
                    view.get("preview"))
        print(f"TESSERA_PROGRESS {k}/{len(job['views'])}", flush=True)


main(sys.argv[sys.argv.index("--") + 1:])

"""Run by a separate Blender process (never imported by the add-on): render one object alone with Cycles through an
orthographic camera into a multilayer EXR with its Combined, Depth and Normal passes.

Arguments after ``--``: blend file, object name, output path, resolution, samples, camera location (3), forward (3),
up (3), orthographic scale, clip end; or ``--views FILE``, a JSON file with the blend file, object name, resolution,
samples, scale, clip end and a list of views (location, forward, up, out), rendered one after the other (an impostor
atlas). With the bpy module the blend file is opened here; with the blender binary it is opened on the command line
and named again here.
"""

import json
import sys

import bpy
from mathutils import Matrix, Vector


def setup(blend, name, res, samples):
    if bpy.data.filepath != blend:
        bpy.ops.wm.open_mainfile(filepath=blend)
    scene = bpy.context.scene
    target = bpy.data.objects[name]
    for ob in scene.objects:  # the object alone (lights stay: they light it)
        if ob.type not in {"LIGHT"} and ob is not target:
            ob.hide_render = True
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = int(samples)
    scene.render.resolution_x = scene.render.resolution_y = int(res)
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


def render_view(scene, loc, fwd, up, scale, clip, out):
    cam_data = bpy.data.cameras.new("tessera_board_camera")
    cam_data.type, cam_data.ortho_scale, cam_data.clip_start, cam_data.clip_end = "ORTHO", scale, 1e-4, clip
    cam = bpy.data.objects.new("tessera_board_camera", cam_data)
    scene.collection.objects.link(cam)
    loc, fwd, up = Vector(loc), Vector(fwd), Vector(up)
    right = fwd.cross(up).normalized()
    cam.matrix_world = Matrix((
        (right.x, up.x, -fwd.x, loc.x), (right.y, up.y, -fwd.y, loc.y), (right.z, up.z, -fwd.z, loc.z), (0, 0, 0, 1)))
    scene.camera = cam
    scene.render.filepath = out
    bpy.ops.render.render(write_still=True)
    bpy.data.objects.remove(cam)
    bpy.data.cameras.remove(cam_data)


def main(argv):
    if argv[0] == "--views":
        with open(argv[1], encoding="utf-8") as f:
            job = json.load(f)
        scene = setup(job["blend"], job["object"], job["resolution"], job["samples"])
        for view in job["views"]:
            render_view(scene, view["location"], view["forward"], view["up"], job["scale"], job["clip"], view["out"])
        return
    blend, name, out, res, samples = argv[:5]
    nums = [float(x) for x in argv[5:]]
    scene = setup(blend, name, res, samples)
    render_view(scene, nums[0:3], nums[3:6], nums[6:9], nums[9], nums[10], out)


main(sys.argv[sys.argv.index("--") + 1:])

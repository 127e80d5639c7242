"""Run by a separate Blender process (never imported by the add-on): render one object alone with Cycles through an
orthographic camera into a multilayer EXR with its Combined, Depth and Normal passes.

Arguments after ``--``: blend file, object name, output path, resolution, samples, camera location (3), forward (3),
up (3), orthographic scale, clip end. With the bpy module the first argument is opened here; with the blender binary
it is opened on the command line and repeated here.
"""

import sys

import bpy
from mathutils import Matrix, Vector


def main(argv):
    blend, name, out, res, samples = argv[:5]
    nums = [float(x) for x in argv[5:]]
    loc, fwd, up, scale, clip = Vector(nums[0:3]), Vector(nums[3:6]), Vector(nums[6:9]), nums[9], nums[10]
    if bpy.data.filepath != blend:
        bpy.ops.wm.open_mainfile(filepath=blend)
    scene = bpy.context.scene
    target = bpy.data.objects[name]
    for ob in scene.objects:  # the object alone (lights stay: they light it)
        if ob.type not in {"LIGHT"} and ob is not target:
            ob.hide_render = True
    cam_data = bpy.data.cameras.new("tessera_board_camera")
    cam_data.type, cam_data.ortho_scale, cam_data.clip_start, cam_data.clip_end = "ORTHO", scale, 1e-4, clip
    cam = bpy.data.objects.new("tessera_board_camera", cam_data)
    scene.collection.objects.link(cam)
    right = fwd.cross(up).normalized()
    cam.matrix_world = Matrix((
        (right.x, up.x, -fwd.x, loc.x), (right.y, up.y, -fwd.y, loc.y), (right.z, up.z, -fwd.z, loc.z), (0, 0, 0, 1)))
    scene.camera = cam
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
    scene.render.filepath = out
    bpy.ops.render.render(write_still=True)


main(sys.argv[sys.argv.index("--") + 1:])

"""Run in a fresh Blender process by `test_blender_bad_files`: enable Tessera from the dev repository, read one
(possibly corrupt) file through *Terrain from Height Map* and *Add Displacement Map*, and print one RESULT line
(JSON) per operator: its outcome, its message and what it left in the scene. A crash shows as a bad exit code.

Usage: python bad_file_case.py REPO_DIR FILE
"""

import json
import sys
from pathlib import Path

import bpy
import numpy as np


def scene_state():
    return {"objects": sorted(o.name for o in bpy.data.objects), "meshes": sorted(m.name for m in bpy.data.meshes),
            "images": sorted(i.name for i in bpy.data.images)}


def run(op, **kw):
    before = scene_state()
    try:
        outcome, message = sorted(op(**kw)), ""
    except RuntimeError as err:
        outcome, message = ["CANCELLED"], str(err)
    return {"outcome": outcome, "message": message, "changed": scene_state() != before, "finite": finite()}


def finite():
    """Every vertex and image pixel in the scene is finite."""
    for me in bpy.data.meshes:
        co = np.empty(len(me.vertices) * 3, np.float32)
        me.vertices.foreach_get("co", co)
        if not np.isfinite(co).all():
            return False
    for image in bpy.data.images:
        if image.size[0] * image.size[1]:
            px = np.empty(image.size[0] * image.size[1] * image.channels, np.float32)
            image.pixels.foreach_get(px)
            if not np.isfinite(px).all():
                return False
    return True


def main(repo_dir, path):
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
    from source_tree import enable_extension

    enable_extension(repo_dir, "tessera_dev")
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    terrain = run(bpy.ops.tessera.terrain_add, source="FILE", filepath=path, tile_size=16, culling=False)
    print("RESULT " + json.dumps({"operator": "terrain_add", **terrain}), flush=True)
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    bpy.ops.mesh.primitive_plane_add()
    displacement = run(bpy.ops.tessera.displacement_add, filepath=path)
    print("RESULT " + json.dumps({"operator": "displacement_add", **displacement}), flush=True)


if __name__ == "__main__":
    main(*sys.argv[-2:])

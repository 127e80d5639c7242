"""Undo and redo around every creating operator, in the ``bpy`` module (tier: blender): each step undoes to the
scene before it and redoes to the scene after it, and the process ends normally. Run in a process of its own, as a
user's session is: undo rebuilds the whole of ``bpy.data``."""

import json
import subprocess
import sys

import pytest
from conftest import REPO_DIR, ROOT

pytestmark = pytest.mark.blender

SCRIPT = r"""
import json, sys
sys.path[:0] = [REPO, TOOLS]
import bpy
from source_tree import enable_extension
enable_extension(REPO, "undo")
ops = bpy.ops.tessera

def counts():
    return [len(bpy.data.objects), len(bpy.data.meshes), len(bpy.data.curves), len(bpy.data.images)]

def active(name):
    for o in bpy.context.view_layer.objects:
        o.select_set(False)
    ob = bpy.data.objects[name]
    ob.select_set(True)
    bpy.context.view_layer.objects.active = ob

def suzanne():
    bpy.ops.mesh.primitive_monkey_add()
    return bpy.context.active_object.name

def curve():
    bpy.ops.curve.primitive_bezier_circle_add()
    return bpy.context.active_object.name

def surface():
    bpy.ops.surface.primitive_nurbs_surface_sphere_add()
    return bpy.context.active_object.name

def live():
    ops.parametric_surface_add(output="LIVE")
    return bpy.context.active_object.name

CASES = [
    ("parametric_surface_add MESH", None, lambda: ops.parametric_surface_add(output="MESH")),
    ("parametric_surface_add LIVE", None, lambda: ops.parametric_surface_add(output="LIVE")),
    ("parametric_surface_bake", live, lambda: ops.parametric_surface_bake()),
    ("tessellate", suzanne, lambda: ops.tessellate(level=2)),
    ("loop_subdivide", suzanne, lambda: ops.loop_subdivide(levels=1)),
    ("tubes", curve, lambda: ops.tubes(radius=0.05)),
    ("curve_adaptive", curve, lambda: ops.curve_adaptive()),
    ("surface_tessellate", surface, lambda: ops.surface_tessellate()),
    ("vector_field_texture", None, lambda: ops.vector_field_texture(width=64, height=64)),
]
results = {}
for name, setup, run in CASES:
    bpy.ops.wm.read_homefile(use_empty=True)
    if setup is not None:
        active(setup())
    bpy.ops.ed.undo_push(message="before " + name)
    before = counts()
    result = sorted(run())
    bpy.ops.ed.undo_push(message=name)
    after = counts()
    bpy.ops.ed.undo()
    undone = counts()
    bpy.ops.ed.redo()
    redone = counts()
    results[name] = {"result": result, "before": before, "after": after, "undone": undone, "redone": redone}
print("RESULT" + json.dumps(results), flush=True)
"""


def test_every_creating_operator_undoes_and_redoes(tmp_path):
    head = f"REPO = {str(REPO_DIR)!r}\nTOOLS = {str(ROOT / 'tools')!r}\n"
    proc = subprocess.run([sys.executable, "-c", head + SCRIPT], capture_output=True, text=True, timeout=600,
                          cwd=str(tmp_path))
    lines = [line for line in proc.stdout.splitlines() if line.startswith("RESULT")]
    assert proc.returncode == 0 and lines, proc.stdout[-3000:] + proc.stderr[-3000:]
    for name, r in json.loads(lines[-1][len("RESULT"):]).items():
        assert r["result"] == ["FINISHED"], (name, r)
        assert r["after"] != r["before"], (name, r)  # it made something
        assert r["undone"] == r["before"] and r["redone"] == r["after"], (name, r)

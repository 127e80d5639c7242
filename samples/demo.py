"""Tessera demo, headless: tessellate Suzanne, export it with Blender's exporters, render a picture.

Run with ``make demo`` (or ``.venv/bin/python samples/demo.py`` after ``make setup``; also works as
``blender --background --python samples/demo.py``). Writes ``out/demo.glb``, ``out/demo.obj`` (+ .mtl)
and ``out/demo.png``: the original Suzanne on the left, the tessellated one on the right, each with its
wireframe drawn over it.
"""

import os
import sys
import tempfile
import time
from pathlib import Path

import bpy

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "out"
LEVEL = 3


def enable_addon():
    """Enable the source tree as an extension (a dev repo holding a link named after the package id)."""
    import addon_utils

    repo = Path(tempfile.mkdtemp(prefix="tessera-demo-repo-"))
    (repo / "tessera").symlink_to(ROOT, target_is_directory=True)
    bpy.context.preferences.extensions.repos.new(name="tessera_demo", module="tessera_demo",
                                                 custom_directory=str(repo), source="USER")
    if addon_utils.enable("bl_ext.tessera_demo.tessera", default_set=True, handle_error=None) is None:
        sys.exit("demo: the Tessera add-on failed to enable")


def material(name, rgba):
    mat = bpy.data.materials.new(name)
    mat.diffuse_color = rgba
    return mat


def wire_overlay(ob, mat):
    """A copy of ``ob`` drawn as thin wires (Wireframe modifier) so the triangles show in a render."""
    wire = bpy.data.objects.new(f"{ob.name}.wire", ob.data)
    bpy.context.scene.collection.objects.link(wire)
    wire.matrix_basis = ob.matrix_basis.copy()  # matrix_world is stale until the depsgraph updates
    mod = wire.modifiers.new("Wire", "WIREFRAME")
    mod.thickness = 0.006
    mod.use_replace = True
    mod.use_even_offset = False
    mod.material_offset = 0
    wire.material_slots[0].link = "OBJECT"
    wire.material_slots[0].material = mat
    return wire


def build_scene():
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_monkey_add(location=(-1.3, 0.0, 0.0), rotation=(0.0, 0.0, 0.35))
    source = bpy.context.active_object
    source.name = "Suzanne"
    bpy.ops.object.shade_smooth()
    source.data.materials.append(material("Clay", (0.8, 0.55, 0.35, 1.0)))
    t0 = time.perf_counter()
    result = bpy.ops.tessera.tessellate(method="LINEAR", level=LEVEL, output="NEW_OBJECT")
    elapsed = time.perf_counter() - t0
    if result != {"FINISHED"}:
        sys.exit(f"demo: tessellate returned {result}")
    tess = bpy.context.active_object
    tess.location.x = 1.3
    wire_mat = material("Wire", (0.05, 0.05, 0.08, 1.0))
    for ob in (source, tess):
        wire_overlay(ob, wire_mat)

    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(cam)
    cam.location = (0.0, -8.6, 0.55)
    cam.rotation_euler = (1.5, 0.0, 0.0)
    cam.data.lens = 50
    scene.camera = cam
    return source, tess, elapsed


def export(tess):
    for ob in bpy.context.scene.objects:
        ob.select_set(ob is tess)
    bpy.context.view_layer.objects.active = tess
    bpy.ops.export_scene.gltf(filepath=str(OUT / "demo.glb"), export_format="GLB", use_selection=True)
    bpy.ops.wm.obj_export(filepath=str(OUT / "demo.obj"), export_selected_objects=True)


def render():
    scene = bpy.context.scene
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.display.shading.light = "STUDIO"
    scene.display.shading.color_type = "MATERIAL"
    scene.display.shading.show_specular_highlight = False
    scene.render.resolution_x, scene.render.resolution_y = 1280, 620
    scene.render.film_transparent = False
    scene.world = scene.world or bpy.data.worlds.new("World")
    scene.world.color = (0.9, 0.9, 0.92)
    scene.render.filepath = str(OUT / "demo.png")
    bpy.ops.render.render(write_still=True)


def main():
    OUT.mkdir(exist_ok=True)
    os.environ.setdefault("TESSERA_OPENCL", "1")
    enable_addon()
    source, tess, elapsed = build_scene()
    export(tess)
    render()
    n_in = len(source.data.polygons)
    n_out = len(tess.data.polygons)
    print(f"demo: Suzanne {n_in} faces -> {n_out} triangles at level {LEVEL} in {elapsed:.2f} s")
    for name in ("demo.glb", "demo.obj", "demo.png"):
        path = OUT / name
        if not path.is_file() or path.stat().st_size == 0:
            sys.exit(f"demo: {path} was not written")
        print(f"demo: wrote {path.relative_to(ROOT)} ({path.stat().st_size:,} bytes)")


if __name__ == "__main__":
    main()

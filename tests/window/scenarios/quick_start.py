"""The README's first quick start, step by step as printed, in Blender's default scene: the picture beside it comes
from here (``tools/manual_shots.sh``), and ``test_window_quick_start.py`` checks that the steps give it.

`STEPS` pairs each menu path the README names with the operator that menu entry runs; the test holds the README to
these paths, in this order. Each operator runs as the menu runs it, invoked in the 3D viewport (from Python, so no redo
panel opens). Shots: ``shot_quick_start_monkey.png`` (the flat monkey after *Add*) and ``shot_quick_start.png`` (the
3D viewport after *Tessellate*).
"""

import bpy
from common import differing_share, menu_step, shot, silhouette

#: (the README's words, the operator's bl_idname in Python form, its arguments)
STEPS = (
    ("Delete", "object.delete", {"confirm": False}),  # the default cube: "select it, press X, Delete"
    ("Add › Mesh › Monkey", "mesh.primitive_monkey_add", {}),
    ("Object › Shade Smooth", "object.shade_smooth", {}),
    ("Object › Tessera › Tessellate", "tessera.tessellate", {}),
)
VIEW = (1.2, 0.0, 0.55)  # a three-quarter view from the front left, as the README's picture shows it
SETTLE = 0.5


def run(w):
    from mathutils import Euler

    r = w.results
    bpy.context.preferences.system.viewport_aa = "8"  # a picture for the manual, drawn as an artist sees it
    cube = bpy.data.objects.get("Cube")
    r["default_cube"] = cube is not None
    for ob in bpy.data.objects:
        ob.select_set(ob is cube)
    bpy.context.view_layer.objects.active = cube
    w.space.region_3d.view_rotation = Euler(VIEW).to_quaternion()
    w.space.region_3d.view_perspective = "PERSP"
    w.space.region_3d.view_distance = 6.0
    w.space.region_3d.view_location = (0.0, 0.0, 0.0)
    yield SETTLE
    empty = flat = monkey = None
    for words, idname, props in STEPS:
        print(f"@@ {words}", flush=True)
        menu_step(w, words, idname, props)
        yield SETTLE
        if idname == "object.delete":
            empty = shot(w, "empty")
        if idname == "mesh.primitive_monkey_add":
            monkey = bpy.context.active_object
            w.screenshot("shot_quick_start_monkey", w.area)
            flat = shot(w, "monkey")
            r["monkey_pixels"] = int(silhouette(flat, empty).sum())
    result = bpy.context.active_object
    r["result_name"] = result.name
    r["result_faces"] = len(result.data.polygons)
    r["monkey_faces"] = len(monkey.data.polygons)
    r["monkey_hidden"] = monkey.hide_get()
    r["result_visible"] = result.visible_get()
    sharp = result.data.attributes.get("sharp_face")
    r["result_sharp_faces"] = 0 if sharp is None else sum(1 for v in sharp.data if v.value)
    yield SETTLE
    tessellated = shot(w, "tessellated")
    r["result_pixels"] = int(silhouette(tessellated, empty).sum())
    w.screenshot("shot_quick_start", w.area)
    # the artist sees a change: the smooth result differs from the flat monkey over both silhouettes
    r["changed_share"], _ = differing_share(tessellated, flat, empty)

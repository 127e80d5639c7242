"""The manual's worked examples in a real Blender window: each starts from Blender's default scene and runs the menu
entries its page names, in order (`EXAMPLES`), with the sidebar open on its Tessera tab. The pictures go to the manual
through ``tools/manual_shots.sh``: ``shot_<example>_start.png`` before the tool (when a Blender step adds something
first) and ``shot_<example>.png`` after it. ``test_window_worked_examples.py`` holds each page to its steps.
"""

import bpy
from common import menu_step, silhouette

#: example -> (the page in docs/, ((the page's words, operator, arguments), ...)); the last step is Tessera's
EXAMPLES = {
    "tessellation": ("tessellation.md", (
        ("Delete", "object.delete", {"confirm": False}),
        ("Add › Mesh › Monkey", "mesh.primitive_monkey_add", {}),
        ("Object › Shade Smooth", "object.shade_smooth", {}),
        ("Object › Tessera › Tessellate", "tessera.tessellate",
         {"level_mode": "ADAPTIVE", "camera_source": "VIEWPORT", "edge_pixels": 30.0}),
    )),
    "tubes": ("tubes.md", (
        ("Delete", "object.delete", {"confirm": False}),
        ("Add › Curve › Bézier", "curve.primitive_bezier_curve_add", {}),
        ("Object › Tessera › Tubes", "tessera.tubes", {}),
    )),
    "loop": ("subdivision.md", (
        ("Delete", "object.delete", {"confirm": False}),
        ("Add › Mesh › Ico Sphere", "mesh.primitive_ico_sphere_add", {}),
        ("Object › Shade Smooth", "object.shade_smooth", {}),
        ("Object › Tessera › Loop Subdivide", "tessera.loop_subdivide", {}),
    )),
    "node_groups": ("node_groups.md", (
        ("Delete", "object.delete", {"confirm": False}),
        ("Add › Mesh › Monkey", "mesh.primitive_monkey_add", {}),
        ("Object › Shade Smooth", "object.shade_smooth", {}),
        ("Object › Tessera › Add Tessera Node Group", "tessera.node_group_add", {"group": "Tessera PN Triangles"}),
    )),
    "surface": ("surfaces.md", (
        ("Delete", "object.delete", {"confirm": False}),
        ("Add › Tessera › Parametric Surface", "tessera.parametric_surface_add", {}),
    )),
}
SETTLE = 0.5
DISTANCE = {"tubes": 3.5}  # how far the view stands from the origin, where 7 leaves the result small
WIREFRAME = {"tessellation"}  # examples shown with the wireframe overlay: their point is where the triangles go


def _default_scene(w):
    """Blender's default scene again: the cube at the origin, selected and active, beside the camera and light."""
    for ob in list(bpy.data.objects):
        if ob.type not in ("CAMERA", "LIGHT"):
            bpy.data.objects.remove(ob)
    with bpy.context.temp_override(**w.context()):
        bpy.ops.mesh.primitive_cube_add()
    bpy.context.active_object.name = "Cube"


def _open_tessera_tab(w):
    """The sidebar open on its Tessera tab, clicked as an artist clicks it (once: it stays open on that tab)."""
    w.space.show_region_ui = True
    w.redraw(2)
    ui = next(r for r in w.area.regions if r.type == "UI")
    w.click(ui.x + ui.width - 8, w.area.y + w.area.height - 300)


def run(w):
    from mathutils import Euler

    r = w.results
    bpy.context.preferences.system.viewport_aa = "8"
    rv3d = w.space.region_3d
    _open_tessera_tab(w)
    yield SETTLE
    for example, (_, steps) in EXAMPLES.items():
        _default_scene(w)
        rv3d.view_rotation = Euler((1.1, 0.0, 0.7)).to_quaternion()
        rv3d.view_perspective = "PERSP"
        rv3d.view_distance = DISTANCE.get(example, 7.0)
        rv3d.view_location = (0.0, 0.0, 0.0)
        w.space.overlay.show_wireframes = example in WIREFRAME
        yield SETTLE
        for k, (words, idname, props) in enumerate(steps):
            print(f"@@ {example}: {words}", flush=True)
            menu_step(w, words, idname, props)
            yield SETTLE
            if k == 0:
                empty = w.screenshot()
            if k + 1 < len(steps) and k > 0 and steps[k + 1][1].startswith("tessera."):  # before the tool
                w.redraw(2)
                w.screenshot(f"shot_{example}_start", w.area)
        made = bpy.context.active_object
        if example in WIREFRAME:
            made.select_set(False)  # its wires grey, not the selection's orange (it stays active: its panels show)
        r[f"{example}_made"] = made.name
        evaluated = made.evaluated_get(bpy.context.evaluated_depsgraph_get())
        r[f"{example}_faces"] = len(evaluated.data.polygons) if made.type == "MESH" else 0  # with its modifiers
        r[f"{example}_pixels"] = int(silhouette(w.screenshot(), empty).sum())
        w.redraw(2)
        w.screenshot(f"shot_{example}", w.area)
        r[f"{example}_tab"] = next(reg for reg in w.area.regions if reg.type == "UI").active_panel_category

"""The manual's worked examples in a real Blender window: each starts from Blender's default scene and runs the steps
its page names, in order (`EXAMPLES`), with the sidebar open on its Tessera tab. The pictures go to the manual through
``tools/manual_shots.sh``: ``shot_<example>_start.png`` after the first ``start`` steps (when the example names one)
and ``shot_<example>.png`` after the last. ``test_window_worked_examples.py`` holds each page to its steps.

A step is (the page's words, what it runs, arguments). What it runs is an operator (``"mesh.primitive_monkey_add"``),
run from Blender's menu search (F3, its label, Enter) as a click on its menu entry runs it, its arguments the settings
it remembers, so that its redo panel opens as after a click (the pictures show it); ``object.delete`` is X then Enter;
an operator given a ``filepath`` (named from the repository's root) is invoked from Python instead, as its file
browser would run it; ``"tool:<id>"`` (a tool picked in the toolbar, arguments set in its header: the displacement
brush's), ``"drag"`` (a left-button drag across the middle of the viewport, as injected mouse events),
``"panel:<idname>"`` (a sidebar panel opened by a Ctrl+click on its header, which closes the others),
``"check:<path>"`` (a checkbox of the sidebar ticked: the active object's property at that path; the step ends when
its live board is drawn) or ``"editor:<type>"`` (the viewport's editor type changed, arguments set on the new editor:
``{"image": "Vector Field"}``; changed back after the picture).
"""

import time
import unicodedata
from pathlib import Path

import bpy
import numpy as np
from common import menu_step, silhouette

#: example -> (its page in docs/, ((the page's words, what it runs, arguments), ...), steps before the start picture
#: or 0 for none)
EXAMPLES = {
    "tessellation": ("tessellation.md", (
        ("Delete", "object.delete", {"confirm": False}),
        ("Add › Mesh › Monkey", "mesh.primitive_monkey_add", {}),
        ("Object › Shade Smooth", "object.shade_smooth", {}),
        ("Object › Tessera › Tessellate", "tessera.tessellate",
         {"level_mode": "ADAPTIVE", "camera_source": "VIEWPORT", "edge_pixels": 30.0}),
    ), 3),
    "tubes": ("tubes.md", (
        ("Delete", "object.delete", {"confirm": False}),
        ("Add › Curve › Bézier", "curve.primitive_bezier_curve_add", {}),
        ("Object › Tessera › Tubes", "tessera.tubes", {}),
    ), 2),
    "loop": ("subdivision.md", (
        ("Delete", "object.delete", {"confirm": False}),
        ("Add › Mesh › Ico Sphere", "mesh.primitive_ico_sphere_add", {}),
        ("Object › Shade Smooth", "object.shade_smooth", {}),
        ("Object › Tessera › Loop Subdivide", "tessera.loop_subdivide", {}),
    ), 3),
    "node_groups": ("node_groups.md", (
        ("Delete", "object.delete", {"confirm": False}),
        ("Add › Mesh › Monkey", "mesh.primitive_monkey_add", {}),
        ("Object › Shade Smooth", "object.shade_smooth", {}),
        ("Object › Tessera › Add Tessera Node Group", "tessera.node_group_add", {"group": "Tessera PN Triangles"}),
    ), 3),
    "surface": ("surfaces.md", (
        ("Delete", "object.delete", {"confirm": False}),
        ("Add › Tessera › Parametric Surface", "tessera.parametric_surface_add", {}),
    ), 0),
    "displacement": ("displacement.md", (
        ("Delete", "object.delete", {"confirm": False}),
        ("Add › Mesh › Grid", "mesh.primitive_grid_add", {"x_subdivisions": 100, "y_subdivisions": 100, "size": 4.0}),
        ("Object › Tessera › Add Displacement Map", "tessera.displacement_add", {}),
        ("Displacement Brush", "tool:tessera.displacement_brush", {"radius": 80.0}),
        ("drag", "drag", {}),
    ), 4),
    "terrain": ("terrain.md", (
        ("Delete", "object.delete", {"confirm": False}),
        ("Add › Tessera › Terrain from Height Map", "tessera.terrain_add",
         {"filepath": "docs/samples/ridged_height_map.png", "texel_size": 0.01, "height_scale": 1.0}),
    ), 0),
    "impostors": ("impostors.md", (
        ("Delete", "object.delete", {"confirm": False}),
        ("Add › Mesh › Monkey", "mesh.primitive_monkey_add", {}),
        ("Object › Shade Smooth", "object.shade_smooth", {}),
        ("Impostors", "panel:TESSERA_PT_impostors", {}),
        ("Live Nailboard", "check:tessera.nailboard.enabled", {}),
    ), 3),
    "vector_field": ("vector_field.md", (
        ("Add › Tessera › Vector Field Texture", "tessera.vector_field_texture", {}),
        ("Image Editor", "editor:IMAGE_EDITOR", {"image": "Vector Field"}),
    ), 0),
}
SETTLE = 0.5
BOARD_S = 120.0  # the longest wait for a live board's first render (about 8 s on two cores)
ROOT = Path(__file__).resolve().parents[3]  # the working tree, where a step's file lies
DISTANCE = {"tubes": 3.5, "terrain": 9.0}  # how far the view stands from the origin, where 7 leaves the result small
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


def _drag(w):
    """Drag with the left button across the middle of the viewport, from left to right, as a hand does it."""
    region = w.region
    y = region.y + region.height // 2
    x0, x1 = region.x + region.width // 2 - 220, region.x + region.width // 2 + 220
    w.event("MOUSEMOVE", "NOTHING", x=x0, y=y)
    yield SETTLE
    w.event("LEFTMOUSE", "PRESS", x=x0, y=y)
    yield 0.1
    for k in range(1, 25):
        w.event("MOUSEMOVE", "NOTHING", x=x0 + (x1 - x0) * k // 24, y=y)
        yield 0.05
    w.event("LEFTMOUSE", "RELEASE", x=x1, y=y)
    yield SETTLE
    w.event("MOUSEMOVE", "NOTHING", x=x1, y=region.y + 40)  # the cursor off the stroke: its ring out of the way


def _boards_drawn(w, limit=BOARD_S):
    """Wait (redrawing) until every live nailboard has its first board drawn, ``limit`` seconds at most."""
    preview = w.module("addon.impostors.preview")
    start = time.monotonic()
    while time.monotonic() - start < limit:
        w.redraw()
        if all(preview.board_drawn(ob) for ob in bpy.data.objects if ob.session_uid in preview.MANAGER.boards):
            break
        yield 0.5
    w.results["boards_drawn_s"] = round(time.monotonic() - start, 1)
    w.results["boards_ready"] = sum(live.images is not None for live in preview.MANAGER.boards.values())


def _open_panel(w, words, idname):
    """Ctrl+click the header of the sidebar panel ``idname``, as an artist opens it: it opens and the others close.
    The header is found in a screenshot of the sidebar: Tessera's panels shown for the active object, in their
    order, each after the dark gap Blender draws between two panels."""
    ui = next(reg for reg in w.area.regions if reg.type == "UI")
    with bpy.context.temp_override(**dict(w.context(), region=ui)):
        shown = [panel for panel in (getattr(bpy.types, name, None) for name in w.module("addon.sidebar").PANEL_ORDER)
                 if panel is not None and panel.poll(bpy.context)]
    index = [panel.bl_idname for panel in shown].index(idname)
    w.results.setdefault("panels", {})[words] = shown[index].bl_label
    w.redraw(2)
    # the darkest of a few columns just inside the panels' left edge (the viewport shows through the sidebar)
    column = w.screenshot(region=ui)[:, 14:21].astype(np.int16).max(axis=2).min(axis=1)
    gaps = [y for y in range(1, len(column) - 3) if column[y - 1] - column[y] > 10 and column[y + 2] - column[y] > 10]
    # a panel's top edge: the first panel's where the sidebar starts, each other's just after the gap before it
    top = gaps[index - 1] + 3 if index else next(y for y in range(len(column)) if column[y] > 55)
    x, y = ui.x + 60, ui.y + ui.height - (top + 12)
    w.event("MOUSEMOVE", "NOTHING", x=x, y=y)
    w.event("LEFT_CTRL", "PRESS", x=x, y=y)
    w.key("LEFTMOUSE", x, y, ctrl=True)
    w.event("LEFT_CTRL", "RELEASE", x=x, y=y)
    yield SETTLE
    w.event("MOUSEMOVE", "NOTHING", x=w.region.x + 40, y=w.region.y + 40)  # off the sidebar: no highlight


def _typed(w, text, x, y):
    """Type ``text`` (letters, accented too, and spaces) with injected key events at window point (x, y)."""
    for char in text:
        plain = unicodedata.normalize("NFKD", char)[0].upper()  # é: the E key, typing é
        key = "SPACE" if char == " " else plain
        w.key(key, x, y, unicode=char)


def _searched(w, words, idname, props):
    """Run operator ``idname`` from Blender's menu search (F3, its label, Enter), as a click on its menu entry runs it:
    its redo panel opens (opened further when collapsed). ``props`` become the settings the operator remembers, which
    a run from a menu starts from. Fails when the search ran another operator."""
    module, name = idname.split(".")
    op = getattr(getattr(bpy.ops, module), name)
    label = op.get_rna_type().name
    w.results.setdefault("labels", {})[words] = label
    wm = bpy.context.window_manager
    last = wm.operator_properties_last(idname)
    for key, value in props.items():
        setattr(last, key, value)
    x, y = w.region.x + w.region.width // 2, w.region.y + w.region.height // 2
    w.event("MOUSEMOVE", "NOTHING", x=x, y=y)
    if idname == "object.delete":  # X asks to confirm; Enter confirms
        props = {}
        w.key("X", x, y)
    else:
        w.key("F3", x, y)
        yield SETTLE
        submenu = w.module("addon.menus").ENUM_MENUS.get(idname)  # a menu entry per item: type the item's name too
        _typed(w, f"{label} {props[submenu]}" if submenu in props else label, x, y)
    yield SETTLE
    w.key("RET", x, y)
    yield SETTLE
    ran = wm.operators[-1].bl_idname if len(wm.operators) else None
    if ran != op.idname():
        raise RuntimeError(f"the menu search for {label!r} ran {ran}, not {op.idname()}")
    used = wm.operators[-1].properties
    wrong = {key: getattr(used, key) for key, value in props.items()
             if (abs(getattr(used, key) - value) > 1e-6 if isinstance(value, float) else getattr(used, key) != value)}
    if wrong:
        raise RuntimeError(f"the menu search ran {label} with {wrong}, not {props}")
    hud = next((reg for reg in w.area.regions if reg.type == "HUD"), None)
    if hud is None:
        raise RuntimeError(f"no redo panel after {label}")
    if hud.height < 40:  # collapsed to its header: open it, as the artist's click on the header does
        w.click(hud.x + 20, hud.y + hud.height - 10)
        yield SETTLE
    w.event("MOUSEMOVE", "NOTHING", x=w.region.x + w.region.width - 60, y=y)  # off the panel: no highlight


def _step(w, words, what, props):
    """Run one step of an example; a generator where the step takes events (yield from it)."""
    if what.startswith("tool:"):
        with bpy.context.temp_override(**w.context()):
            bpy.ops.wm.tool_set_by_id(name=what[len("tool:"):])
        for name, value in props.items():
            setattr(bpy.context.scene.tessera.brush, name, value)
        from bl_ui.space_toolsystem_common import ToolSelectPanelHelper

        helper = ToolSelectPanelHelper._tool_class_from_space_type("VIEW_3D")
        item, tool, _ = helper._tool_get_active(bpy.context, "VIEW_3D", "OBJECT")
        w.results.setdefault("tools", {})[words] = [tool.idname, item.label]  # the active tool and its button's label
        return ()
    if what == "drag":
        return _drag(w)
    if what.startswith("panel:"):
        return _open_panel(w, words, what[len("panel:"):])
    if what.startswith("check:"):
        owner, _, name = what[len("check:"):].rpartition(".")
        ob = bpy.context.active_object
        target = ob.path_resolve(owner) if owner else ob
        setattr(target, name, True)
        w.results.setdefault("checks", {})[words] = target.bl_rna.properties[name].name
        return _boards_drawn(w)
    if what.startswith("editor:"):
        area = w.area
        area.ui_type = what[len("editor:"):]
        for name, value in props.items():
            setattr(area.spaces.active, name, bpy.data.images[value] if name == "image" else value)
        w.results.setdefault("editors", {})[words] = area.type
        return ()
    if "filepath" in props:  # a file of this repository, named from its root: as the file browser runs it
        menu_step(w, words, what, dict(props, filepath=str(ROOT / props["filepath"])))
        return ()
    return _searched(w, words, what, props)


def run(w):
    from mathutils import Euler

    r = w.results
    bpy.context.preferences.system.viewport_aa = "8"
    rv3d = w.space.region_3d
    _open_tessera_tab(w)
    yield SETTLE
    for example, (_, steps, start) in EXAMPLES.items():
        _default_scene(w)
        rv3d.view_rotation = Euler((1.1, 0.0, 0.7)).to_quaternion()
        rv3d.view_perspective = "PERSP"
        rv3d.view_distance = DISTANCE.get(example, 7.0)
        rv3d.view_location = (0.0, 0.0, 0.0)
        w.space.overlay.show_wireframes = example in WIREFRAME
        yield SETTLE
        area = w.area
        for k, (words, what, props) in enumerate(steps):
            print(f"@@ {example}: {words}", flush=True)
            yield from _step(w, words, what, props)
            yield SETTLE
            if k == 0:
                empty, empty_hud = w.screenshot(), _hud(w)
            if k + 1 == start:
                w.redraw(2, area)
                w.screenshot(f"shot_{example}_start", area)
            if what == "drag":
                r[f"{example}_map_texels_changed"] = _map_changed(bpy.context.active_object)
        made = bpy.context.active_object
        if example in WIREFRAME:
            made.select_set(False)  # its wires grey, not the selection's orange (it stays active: its panels show)
        if area.type == "VIEW_3D":
            r[f"{example}_made"] = made.name
            evaluated = made.evaluated_get(bpy.context.evaluated_depsgraph_get())
            r[f"{example}_faces"] = len(evaluated.data.polygons) if made.type == "MESH" else 0  # with modifiers
            if made.type == "MESH":
                evaluated.data.calc_loop_triangles()
                r[f"{example}_triangles"] = len(evaluated.data.loop_triangles)
            r[f"{example}_pixels"] = _scene_pixels(w.screenshot(), empty, (empty_hud, _hud(w)))
        else:  # an image shown in its editor
            image = area.spaces.active.image
            pixels = np.array(image.pixels[:], np.float32).reshape(image.size[1], image.size[0], 4)
            r[f"{example}_made"] = image.name
            r[f"{example}_image_spread"] = float(pixels[..., :3].std())
        w.redraw(2, area)
        w.screenshot(f"shot_{example}", area)
        if area.type == "VIEW_3D":
            r[f"{example}_tab"] = next(reg for reg in area.regions if reg.type == "UI").active_panel_category
        else:
            area.ui_type = "VIEW_3D"
        with bpy.context.temp_override(**w.context()):
            bpy.ops.wm.tool_set_by_id(name="builtin.select_box")  # Blender's default tool for the next example
        yield SETTLE


def _hud(w):
    """The redo panel's rectangle in viewport screenshots as (rows, columns) slices, or None when none is shown."""
    region = w.region
    for hud in (reg for reg in w.area.regions if reg.type == "HUD" and reg.width > 1):
        top = max(0, region.y + region.height - (hud.y + hud.height))
        left = max(0, hud.x - region.x)
        return slice(top, top + hud.height), slice(left, left + hud.width)
    return None


def _scene_pixels(image, empty, huds):
    """Pixels where ``image`` shows something ``empty`` does not, outside the redo panels ``huds`` of either."""
    image, empty = image.copy(), empty.copy()
    for hud in filter(None, huds):
        image[hud] = empty[hud] = 0
    return int(silhouette(image, empty).sum())


def _map_changed(ob):
    """How many texels of ``ob``'s displacement map are away from zero height."""
    image = ob.tessera.displacement.image
    return int((np.abs(np.array(image.pixels[:], np.float32).reshape(-1, 4)[:, 0]) > 1e-6).sum())

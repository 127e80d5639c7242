"""The window bench (``bench/window.py`` runs it): what a redraw of the 3D viewport costs with each preview on,
against Blender drawing that preview's applied mesh in the same window and run (``wm.redraw_timer``, the viewport
region alone); and the longest the main thread is held during an impostor bake and a live board's render, against
one redraw. Writes its rows into ``results["rows"]``."""

import time

import bpy
from common import REDRAWS, clean_scene, frame, operate, region_ms, sun_light, tube_circle
from mathutils import Euler
from previews import _copy_of, height_image, setter

HOLD_TIMEOUT_S = 180.0


def triangles(ob):
    ob.data.calc_loop_triangles()
    return len(ob.data.loop_triangles)


def cost(w, name, source, preview, applied, selected=False):
    """One row: the viewport with ``preview(True)`` against the object ``applied()`` makes (``source`` hidden);
    ``selected``: each object selected and active, so both draw their selection outline."""
    layer = bpy.context.view_layer

    def select(ob):
        ob.select_set(selected)
        layer.objects.active = ob if selected else None

    select(source)
    preview(True)
    with_preview = region_ms(w)
    preview(False)
    source.select_set(False)
    made = applied()
    select(made)
    source.hide_set(True)
    blender = region_ms(w)
    row = {"case": f"redraw, {name} preview{', selected' if selected else ''}", "triangles": triangles(made),
           "preview_ms": round(with_preview, 2), "blender_ms": round(blender, 2),
           "ratio": round(with_preview / blender, 2)}
    bpy.data.objects.remove(made)
    source.hide_set(False)
    return row


def hold(w, started, done):
    """Step the event loop as fast as it comes back, from ``started()`` until ``done()``: the longest gap between
    two steps (ms), the time it took (s). A generator (yields to the window): its return value."""
    started()
    start = last = time.perf_counter()
    longest = 0.0
    while not done() and time.perf_counter() - start < HOLD_TIMEOUT_S:
        yield 0.0
        now = time.perf_counter()
        longest, last = max(longest, now - last), now
    return 1000.0 * longest, time.perf_counter() - start


def run(w):
    rows = w.results.setdefault("rows", [])
    clean_scene(w)
    bpy.ops.mesh.primitive_monkey_add()
    ob = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    frame(w, [ob])
    yield 0.3
    ob.tessera.tessellate.level = 3
    for selected in (False, True):
        rows.append(cost(w, "tessellation (PN, level 3)", ob, setter(ob, "tessellate"),
                         lambda: operate(w, bpy.ops.tessera.tessellate, ob, method="PN", level=3), selected))
    ob.tessera.loop.levels = 2
    rows.append(cost(w, "Loop (2 levels)", ob, setter(ob, "loop"),
                     lambda: operate(w, bpy.ops.tessera.loop_subdivide, ob, levels=2)))
    yield 0.3

    clean_scene(w)
    ob, tubes = tube_circle(w)
    rows.append(cost(w, "tubes (16 sides)", ob, setter(ob, "tubes"),
                     lambda: operate(w, bpy.ops.tessera.tubes, ob, **tubes)))
    yield 0.3

    clean_scene(w)
    ob = operate(w, bpy.ops.tessera.terrain_add, source="IMAGE", image_name=height_image(257).name)
    frame(w, [ob], (1.0, 0.0, 0.6))
    rows.append(cost(w, "terrain (257² heights)", ob, setter(ob, "terrain"), lambda: _copy_of(ob)))
    yield 0.3

    # The main thread during background work: an impostor bake, then a live board's first render
    clean_scene(w)
    sun_light()
    bpy.ops.mesh.primitive_monkey_add()
    ob = bpy.context.active_object
    frame(w, [ob], (1.1, 0.0, 0.7))
    yield 0.3
    redraw = region_ms(w)
    before = set(bpy.data.objects)

    def bake():
        with bpy.context.temp_override(**w.context(), active_object=ob, object=ob, selected_objects=[ob]):
            bpy.ops.tessera.impostor_bake("INVOKE_DEFAULT", grid=4, tile=128, samples=8)

    for which in ("first of the session", "again"):  # the first start of a modal job pays Blender's one-time costs
        longest, took = yield from hold(w, bake, lambda: len(set(bpy.data.objects) - before) > 0)
        rows.append({"case": f"impostor bake (4 x 4 views of 128 px, 8 samples), {which}", "seconds": round(took, 1),
                     "longest_hold_ms": round(longest, 1), "redraw_ms": round(redraw, 1),
                     "beyond_redraw_ms": round(max(longest - redraw, 0.0), 1)})
        for made in set(bpy.data.objects) - before:
            bpy.data.objects.remove(made)
        yield 0.3

    preview = w.module("addon.impostors.preview")
    s = ob.tessera.nailboard
    s.samples, s.progressive = 8, True

    def board_ready():
        return preview.board_drawn(ob)

    def enable():
        s.enabled = True

    longest, took = yield from hold(w, enable, board_ready)
    rows.append({"case": "live board, first render (8 samples, progressive)", "seconds": round(took, 1),
                 "longest_hold_ms": round(longest, 1), "redraw_ms": round(redraw, 1),
                 "beyond_redraw_ms": round(max(longest - redraw, 0.0), 1)})
    rv3d = w.space.region_3d

    def orbit():
        rv3d.view_rotation.rotate(Euler((0.0, 0.0, 0.05)))

    steps = []
    for _ in range(10):  # orbit in steps, as a drag does; each step's redraw on the main thread
        orbit()
        steps.append(region_ms(w, 1, warm=False))
        yield 0.02
    rows.append({"case": "live board, orbiting (10 steps of 3°)", "longest_hold_ms": round(max(steps), 1),
                 "redraw_ms": round(region_ms(w), 1), "beyond_redraw_ms": round(max(max(steps) - redraw, 0.0), 1)})
    s.enabled = False
    w.results["redraws_per_row"] = REDRAWS
    w.results["rows_written"] = len(rows)
    yield 0.3

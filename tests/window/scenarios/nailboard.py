"""The live nailboard as an artist meets it: a smooth sphere with *Live Nailboard* on. Records how long the first
board takes, where the board is drawn against where Blender draws the object (masks), that hiding the object hides
its board, the pre-warps made per redraw of an unchanged view (none expected), and what a redraw costs the main
thread with the view unchanged and just after the view moved (the moved eye's pre-warp runs on a worker thread)."""

import bpy
from common import board_drawn_within, clean_scene, frame, mask_mismatch, region_ms, shot, silhouette, sun_light
from mathutils import Euler

SETTLE = 0.3
FIRST_BOARD_S = 120.0


def run(w):
    r = w.results
    preview = w.module("addon.impostors.preview")
    clean_scene(w)
    sun_light()  # the board's render needs a light
    bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24)
    ob = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    frame(w, [ob], (1.1, 0.0, 0.7))
    ob.hide_set(True)
    empty = shot(w, "empty")
    ob.hide_set(False)
    source = shot(w, "object")
    r["redraw_ms_object"] = region_ms(w, 10)  # the baseline: Blender drawing the object itself
    yield SETTLE

    s = ob.tessera.nailboard
    s.samples, s.progressive = 4, False
    s.enabled = True
    r["first_board_s"] = yield from board_drawn_within(w, ob, FIRST_BOARD_S)
    live = preview.MANAGER.boards.get(ob.session_uid)
    r["board_ready"] = bool(live is not None and live.images is not None)
    yield SETTLE

    board = shot(w, "board")
    r["board_vs_object_tiles"], r["board_union_tiles"] = mask_mismatch(board, source, empty)

    count = preview.PREWARP_COUNT[0]
    r["redraw_ms_same_view"] = region_ms(w, 10)
    r["prewarps_per_redraw_same_view"] = (preview.PREWARP_COUNT[0] - count) / 10

    ob.hide_set(True)
    r["hidden_board_pixels"] = int(silhouette(shot(w, "hidden"), empty).sum())
    ob.hide_set(False)

    rv3d = w.space.region_3d
    moved = []
    for _ in range(5):  # orbit a little, as a drag would: each redraw's main-thread time
        rv3d.view_rotation.rotate(Euler((0.0, 0.0, 0.01)))
        moved.append(region_ms(w, 1, warm=False))
        yield 0.05
    r["redraw_ms_moved"] = max(moved)
    r["prewarps_while_orbiting"] = preview.PREWARP_COUNT[0] - count
    yield SETTLE
    s.enabled = False
    yield SETTLE

"""The displacement brush as a sculptor meets it: the tool picked from the toolbar's tool, its ring under the
cursor while hovering, one stroke dragged with injected mouse events, then the cursor moved away. Records the ring's
pixels where the stroke began and where the cursor is (mid-stroke and after), and whether the map changed."""

import bpy
import numpy as np
from common import clean_scene, frame, operate, shot

SETTLE = 0.3


def ring_pixels(image, x, y, half=60):
    """Pixels of the brush ring's orange in the box of ``half`` pixels around region point (x, y) (y from the
    bottom, as events are)."""
    h = image.shape[0]
    top, left = max(0, h - y - half), max(0, x - half)
    box = image[top:h - y + half, left:x + half].astype(np.int16)
    r, g, b = box[..., 0], box[..., 1], box[..., 2]
    return int(((r > 150) & (r - b > 50) & (r - g > 20)).sum())


def run(w):
    r = w.results
    clean_scene(w)
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=40, y_subdivisions=40, size=4.0)
    ob = bpy.context.active_object
    operate(w, bpy.ops.tessera.displacement_add, ob, width=256, height=256)
    bpy.context.view_layer.objects.active = ob
    ob.select_set(False)  # no selection outline: the only orange is the ring
    frame(w, [ob], "TOP")
    bpy.context.view_layer.objects.active = ob
    with bpy.context.temp_override(**w.context()):
        bpy.ops.wm.tool_set_by_id(name="tessera.displacement_brush")
    r["tool"] = bpy.context.workspace.tools.from_space_view3d_mode("OBJECT").idname
    yield SETTLE

    region = w.region
    cx, cy = region.width // 2, region.height // 2
    a, b, c = (cx - 150, cy), (cx + 150, cy), (cx, cy + 200)

    def move(x, y, value="NOTHING", kind="MOUSEMOVE"):
        w.event(kind, value, x=region.x + x, y=region.y + y)

    before = np.array(ob.tessera.displacement.image.pixels[:], np.float32)
    move(*a)
    yield SETTLE
    hover = shot(w, "hover")
    r["hover_ring_at_cursor"] = ring_pixels(hover, *a)

    move(*a, value="PRESS", kind="LEFTMOUSE")
    yield SETTLE
    for t in np.linspace(0.0, 1.0, 12)[1:]:
        move(int(a[0] + t * (b[0] - a[0])), a[1])
        yield 0.05
    yield SETTLE
    mid = shot(w, "mid_stroke")
    r["mid_stroke_ring_at_start"] = ring_pixels(mid, *a)
    r["mid_stroke_ring_at_cursor"] = ring_pixels(mid, *b)
    move(*b, value="RELEASE", kind="LEFTMOUSE")
    yield SETTLE
    move(*c)
    yield SETTLE
    after = shot(w, "after_stroke")
    r["after_ring_at_start"] = ring_pixels(after, *a)
    r["after_ring_at_end"] = ring_pixels(after, *b)
    r["after_ring_at_cursor"] = ring_pixels(after, *c)
    after_pixels = np.array(ob.tessera.displacement.image.pixels[:], np.float32)
    r["map_changed_texels"] = int((np.abs(after_pixels - before) > 1e-6).sum())
    yield SETTLE

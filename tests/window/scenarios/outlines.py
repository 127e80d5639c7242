"""Selection outlines of previews drawn instead of their objects, as an artist meets them: each preview's object
selected and active shows the outline Blender draws around its applied result (selected and active, its source
hidden). The outline is taken as the pixels that change between the object selected and deselected, with object
origins off (the origin dot is not the outline). Recorded per case: ``<name>_outline_preview`` and
``<name>_outline_applied`` (outline pixels) and ``<name>_outline_mismatch`` (`common.mask_mismatch` of the two).
Cases: tessellation (active; selected but not active; half behind a cube, where Blender fades the outline), Loop,
tubes, terrain and the live nailboard."""

import bpy
import numpy as np
from common import THRESHOLD, block_mask, board_drawn_within, clean_scene, frame, operate, shot, sun_light, tube_circle
from previews import _copy_of, height_image

SETTLE = 0.3
FIRST_BOARD_S = 120.0


def outline_mask(w, name, ob, active=True):
    """The pixels that change when ``ob`` is selected (and made active when ``active``, else another object is
    active): (h, w) bool."""
    layer = bpy.context.view_layer
    ob.select_set(False)
    layer.objects.active = None
    plain = shot(w, f"{name}_deselected")
    ob.select_set(True)
    if active:
        layer.objects.active = ob
    selected = shot(w, f"{name}_selected")
    ob.select_set(False)
    layer.objects.active = None
    return (np.abs(selected.astype(np.int16) - plain.astype(np.int16)) > THRESHOLD).any(axis=2)


def compare(w, name, source, preview, applied, active=True):
    """Outline of ``source`` with ``preview(True)`` against the outline of ``applied()`` (a new object; ``source``
    hidden meanwhile)."""
    preview(True)
    with_preview = outline_mask(w, f"{name}_preview", source, active)
    preview(False)
    made = applied()
    source.hide_set(True)
    drawn = outline_mask(w, f"{name}_applied", made, active)
    bpy.data.objects.remove(made)
    source.hide_set(False)
    record(w, name, with_preview, drawn)


def record(w, name, with_preview, drawn):
    """Record both outlines' pixel counts and the share of 8-pixel tiles covered by one only."""
    a, b = block_mask(with_preview, 8), block_mask(drawn, 8)
    union = int((a | b).sum())
    r = w.results
    r[f"{name}_outline_preview"], r[f"{name}_outline_applied"] = int(with_preview.sum()), int(drawn.sum())
    r[f"{name}_outline_mismatch"] = float((a ^ b).sum()) / union if union else 0.0


def setter(ob, group, name="preview"):
    def preview(on):
        setattr(getattr(ob.tessera, group), name, on)

    return preview


def run(w):
    r = w.results
    clean_scene(w)
    w.space.overlay.show_object_origins = False
    r["theme_active"] = list(bpy.context.preferences.themes[0].view_3d.object_active)

    # Tessellation on a smooth Suzanne: active, then selected with another object active, then half behind a cube
    bpy.ops.mesh.primitive_monkey_add()
    ob = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    frame(w, [ob])
    yield SETTLE
    ob.tessera.tessellate.level = 3

    def tessellated():
        return operate(w, bpy.ops.tessera.tessellate, ob, method="PN", level=3)

    compare(w, "tessellation", ob, setter(ob, "tessellate"), tessellated)
    yield SETTLE
    compare(w, "tessellation_selected", ob, setter(ob, "tessellate"), tessellated, active=False)
    yield SETTLE
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.6, -1.5, 0.0))
    cube = bpy.context.active_object
    cube.select_set(False)
    compare(w, "tessellation_behind", ob, setter(ob, "tessellate"), tessellated)
    bpy.data.objects.remove(cube)
    yield SETTLE

    # Loop on the same Suzanne
    ob.tessera.loop.levels = 2
    compare(w, "loop", ob, setter(ob, "loop"), lambda: operate(w, bpy.ops.tessera.loop_subdivide, ob, levels=2))
    yield SETTLE

    # Tubes on a Bézier circle
    clean_scene(w)
    ob, tubes = tube_circle(w)
    yield SETTLE
    compare(w, "tubes", ob, setter(ob, "tubes"), lambda: operate(w, bpy.ops.tessera.tubes, ob, **tubes))
    yield SETTLE

    # A terrain from an image
    clean_scene(w)
    image = height_image()
    ob = operate(w, bpy.ops.tessera.terrain_add, source="IMAGE", image_name=image.name)
    frame(w, [ob], (1.0, 0.0, 0.6))
    yield SETTLE
    compare(w, "terrain", ob, setter(ob, "terrain"), lambda: _copy_of(ob))
    yield SETTLE

    # The live nailboard of a smooth sphere, against the sphere itself (the board stands for it)
    clean_scene(w)
    sun_light()
    bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24)
    ob = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    frame(w, [ob], (1.1, 0.0, 0.7))
    s = ob.tessera.nailboard
    s.samples, s.progressive = 4, False
    s.enabled = True
    yield from board_drawn_within(w, ob, FIRST_BOARD_S)
    yield SETTLE
    with_board = outline_mask(w, "board_preview", ob)
    s.enabled = False
    yield SETTLE
    record(w, "board", with_board, outline_mask(w, "board_applied", ob))

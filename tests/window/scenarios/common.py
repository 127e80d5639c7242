"""What the window scenarios share: a clean scene, a framed view, and the preview oracle.

The oracle (issue "Tessera in a real Blender window", item 2): a screenshot with a preview on is compared with a
screenshot of the applied result drawn by Blender (its source hidden). A pixel differs when a channel differs by
more than 16/255; the share of differing pixels is taken over the union of both silhouettes, each silhouette being
where its screenshot differs from the empty scene's.
"""

import time

import bpy
import numpy as np

THRESHOLD = 16
REDRAWS = 20  # redraws a timing averages over


def clean_scene(w):
    """No objects, no leftover meshes; Solid shading, overlays on except the text (it names the active object, which
    the compared screenshots need not share) and the floor grid with its axes (Mesa's lavapipe draws Blender's grid
    with blocks of garbage in perspective views, different from frame to frame)."""
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    for mesh in list(bpy.data.meshes):
        bpy.data.meshes.remove(mesh)
    w.space.shading.type = "SOLID"
    overlay = w.space.overlay
    overlay.show_text = False
    overlay.show_floor = overlay.show_axis_x = overlay.show_axis_y = False


def frame(w, objects, view="FRONT"):
    """Look at ``objects`` along ``view`` (an axis of numpad 1, 3, 7: "FRONT", "RIGHT", "TOP", or Euler angles in
    radians of a free view) and frame them, as an artist would; nothing stays selected."""
    from mathutils import Euler

    for ob in bpy.data.objects:
        ob.select_set(ob in objects)
    with bpy.context.temp_override(**w.context()):
        if isinstance(view, str):
            bpy.ops.view3d.view_axis(type=view)
        else:
            w.space.region_3d.view_rotation = Euler(view).to_quaternion()
            w.space.region_3d.view_perspective = "PERSP"
        bpy.ops.view3d.view_selected()
    for ob in objects:
        ob.select_set(False)


def silhouette(image, empty):
    """Where ``image`` differs from the empty scene's screenshot: (h, w) bool."""
    return (np.abs(image.astype(np.int16) - empty.astype(np.int16)) > THRESHOLD).any(axis=2)


def differing_share(a, b, empty):
    """The share of pixels that differ between ``a`` and ``b`` over the union of their silhouettes, and the
    union's size in pixels."""
    union = silhouette(a, empty) | silhouette(b, empty)
    differ = (np.abs(a.astype(np.int16) - b.astype(np.int16)) > THRESHOLD).any(axis=2) & union
    count = int(union.sum())
    return (float(differ.sum()) / count if count else 0.0), count


def block_mask(mask, block):
    """Which ``block`` x ``block`` tiles of the bool image ``mask`` hold any True pixel: (h // block, w // block)."""
    h, w = (mask.shape[0] // block) * block, (mask.shape[1] // block) * block
    return mask[:h, :w].reshape(h // block, block, w // block, block).any(axis=(1, 3))


def mask_mismatch(a, b, empty, block=8):
    """Where two drawings cover different parts of the view, for wires and see-through surfaces whose pixels are not
    comparable one by one: the share of ``block``-pixel tiles covered in one silhouette but not the other, over the
    tiles covered in either. A preview drawn in the wrong place, or missing, or fighting its source, differs."""
    ma, mb = block_mask(silhouette(a, empty), block), block_mask(silhouette(b, empty), block)
    union = int((ma | mb).sum())
    return (float((ma ^ mb).sum()) / union if union else 0.0), union


def shot(w, name):
    """A screenshot of the 3D viewport after two redraws."""
    w.redraw(2)
    return w.screenshot(name)


def operate(w, operator, ob=None, **props):
    """Run ``operator`` (e.g. ``bpy.ops.tessera.tubes``) in the 3D viewport on ``ob`` (active and only selected);
    returns the new active object, deselected."""
    override = dict(w.context())
    if ob is not None:
        for other in bpy.data.objects:
            other.select_set(other is ob)
        bpy.context.view_layer.objects.active = ob
        override.update(active_object=ob, object=ob, selected_objects=[ob])
    with bpy.context.temp_override(**override):
        result = operator(**props)
    if result != {"FINISHED"}:
        raise RuntimeError(f"{operator.idname_py()} returned {result}")
    made = bpy.context.view_layer.objects.active
    made.select_set(False)
    return made


def oracle(w, name, empty, preview, applied, source=None, masks=False):
    """The preview oracle: a screenshot with ``preview(True)`` on (then ``preview(False)``) against one of the
    applied result, the object ``applied()`` makes, with ``source`` hidden; the applied object is removed again.
    Records and returns the share of differing pixels over the union of both silhouettes (with ``masks``: of
    differing tiles, `mask_mismatch`)."""
    preview(True)
    with_preview = shot(w, f"{name}_preview")
    preview(False)
    made = applied()
    if source is not None:
        source.hide_set(True)
    result = shot(w, f"{name}_applied")
    bpy.data.objects.remove(made)
    if source is not None:
        source.hide_set(False)
    share, union = (mask_mismatch if masks else differing_share)(with_preview, result, empty)
    w.results[f"{name}_vs_applied"], w.results[f"{name}_union_pixels"] = share, union
    return share


def sun_light():
    """A sun out of view (its gizmo is not what a scenario looks at), for the renders of boards and cards."""
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 4.0
    sun.location = (0.0, 0.0, 100.0)
    sun.rotation_euler = (0.6, 0.2, 0.3)
    bpy.context.collection.objects.link(sun)
    return sun


def tube_circle(w):
    """A Bézier circle with constant tubes of radius 0.15 and 16 sides, framed from above at an angle: the
    object, its tubes' settings as *Tubes* takes them."""
    bpy.ops.curve.primitive_bezier_circle_add()
    ob = bpy.context.active_object
    settings = {"radius_source": "CONSTANT", "radius": 0.15, "sides": 16}
    for name, value in settings.items():
        setattr(ob.tessera.tubes, name, value)
    frame(w, [ob], (0.9, 0.0, 0.5))
    return ob, settings


def board_drawn_within(w, ob, limit):
    """Redraw until ``ob``'s live board is drawn (`addon.impostors.preview.board_drawn`), ``limit`` seconds at most.
    A generator returning the seconds it took."""
    preview = w.module("addon.impostors.preview")
    start = time.monotonic()
    while time.monotonic() - start < limit:
        w.redraw()
        if preview.board_drawn(ob):
            break
        yield 0.5
    return time.monotonic() - start


def after_startup(w, timeout=120.0):
    """Yield until the add-on's start-up work is done (its node-group library written by a worker Blender), so that
    timings do not share the CPU with it. A generator."""
    library = w.module("addon.node_library")
    start = time.perf_counter()
    while library._writer and time.perf_counter() - start < timeout:
        yield 0.25


def region_ms(w, iterations=REDRAWS, warm=True):
    """Milliseconds of main-thread time per redraw of the 3D viewport region; ``warm``: after two redraws that are
    not counted (uploads and level selections happen there), else counting the first redraw of what changed."""
    with bpy.context.temp_override(**w.context()):
        if warm:
            bpy.ops.wm.redraw_timer(type="DRAW", iterations=2)
        start = time.perf_counter()
        bpy.ops.wm.redraw_timer(type="DRAW", iterations=iterations)
    return 1000.0 * (time.perf_counter() - start) / iterations


def menu_step(w, words, idname, props):
    """Run operator ``idname`` (``"mesh.primitive_monkey_add"``) with ``props`` as its menu entry runs it: invoked in
    the 3D viewport. Records in ``w.results["labels"]`` the label Blender gives the operator under ``words`` (the
    menu path the manual prints), so a test can hold the path's last item to it."""
    module, name = idname.split(".")
    op = getattr(getattr(bpy.ops, module), name)
    w.results.setdefault("labels", {})[words] = op.get_rna_type().name
    with bpy.context.temp_override(**w.context()):
        result = op("INVOKE_DEFAULT", **props)
    if result != {"FINISHED"}:
        raise RuntimeError(f"{idname} returned {result}")

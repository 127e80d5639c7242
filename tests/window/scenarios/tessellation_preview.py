"""The tessellation live preview on a smooth Suzanne, as an artist meets it: against the applied result drawn by
Blender, hidden with its source, in Local View of another object, with an Array modifier, and in Edit Mode."""

import bpy
from common import clean_scene, differing_share, frame, operate, oracle, shot, silhouette

SETTLE = 0.3  # seconds between steps: the window draws in between


def tessellation_oracle(w, ob, empty, name, masks=False, **op):
    """The oracle for ``ob``'s tessellation preview against *Tessellate* with ``op``."""

    def preview(on):
        ob.tessera.tessellate.preview = on
        w.redraw()

    return oracle(w, name, empty, preview, lambda: operate(w, bpy.ops.tessera.tessellate, ob, **op), source=ob,
                  masks=masks)


def run(w):
    r = w.results
    clean_scene(w)
    bpy.ops.mesh.primitive_monkey_add()
    ob = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    frame(w, [ob])
    yield SETTLE

    ob.hide_set(True)
    empty = shot(w, "empty")
    ob.hide_set(False)
    source = shot(w, "source")
    s = ob.tessera.tessellate
    s.level = 3
    tessellation_oracle(w, ob, empty, "uniform", method="PN", level=3)
    yield SETTLE
    w.space.shading.light = "MATCAP"
    s.preview = True  # the first MatCap frame asks a timer to read the MatCap
    yield SETTLE
    s.preview = False
    tessellation_oracle(w, ob, empty, "matcap", method="PN", level=3)
    w.space.shading.light = "STUDIO"
    yield SETTLE
    s.level_mode = "ADAPTIVE"
    tessellation_oracle(w, ob, empty, "adaptive", method="PN", level_mode="ADAPTIVE", camera_source="VIEWPORT")
    s.level_mode = "UNIFORM"
    yield SETTLE
    # Wireframe shows the preview's wire and X-ray its see-through surface, as they show the applied mesh's
    w.space.shading.type = "WIREFRAME"
    tessellation_oracle(w, ob, empty, "wireframe", masks=True, method="PN", level=3)
    w.space.shading.type = "SOLID"
    w.space.shading.show_xray = True
    tessellation_oracle(w, ob, empty, "xray", masks=True, method="PN", level=3)
    w.space.shading.show_xray = False
    yield SETTLE
    with bpy.context.temp_override(**w.context(), active_object=ob, object=ob, selected_objects=[ob]):
        bpy.ops.tessera.tessellate(method="PN", level=3)
    applied_ob = bpy.context.active_object
    applied_ob.select_set(False)
    ob.hide_set(True)
    r["source_vs_applied"], _ = differing_share(source, shot(w, "applied"), empty)
    yield SETTLE

    # Hiding the source hides its preview, as it hides a modifier's result.
    applied_ob.hide_set(True)
    s.preview = True
    yield SETTLE
    hidden = shot(w, "hidden_with_preview")
    r["hidden_source_pixels"] = int(silhouette(hidden, empty).sum())

    # Panels of the hidden active object stay reachable.
    bpy.context.view_layer.objects.active = ob
    panel_module = w.module("addon.tessellation.panel")
    with bpy.context.temp_override(**w.context()):
        r["panel_shown_for_hidden_source"] = bool(panel_module.TESSERA_PT_tessellation.poll(bpy.context))

    # Local View of another object shows only that object.
    ob.hide_set(False)
    other = applied_ob
    other.hide_set(False)
    other.location.x = 3.0
    for o in bpy.data.objects:
        o.select_set(o is other)
    bpy.context.view_layer.objects.active = other
    with bpy.context.temp_override(**w.context()):
        bpy.ops.view3d.localview(frame_selected=False)
    other.hide_set(True)  # inside Local View the other object is hidden too: nothing should show
    yield SETTLE
    local = shot(w, "local_view_other")
    r["local_view_foreign_pixels"] = int(silhouette(local, empty).sum())
    other.hide_set(False)
    with bpy.context.temp_override(**w.context()):
        bpy.ops.view3d.localview(frame_selected=False)
    bpy.data.objects.remove(other)
    s.preview = False
    yield SETTLE

    # The preview follows the modifier stack the operator uses: an Array of 3 shows three monkeys.
    array = ob.modifiers.new("Array", "ARRAY")
    array.count = 3
    frame(w, [ob])
    ob.hide_set(True)
    empty_array = shot(w, "array_empty")
    ob.hide_set(False)
    tessellation_oracle(w, ob, empty_array, "array", method="PN", level=3)
    ob.modifiers.remove(array)
    frame(w, [ob])
    yield SETTLE

    # Edit Mode with the preview on: the edit cage, and no error in the log.
    s.preview = True
    for o in bpy.data.objects:
        o.select_set(o is ob)
    bpy.context.view_layer.objects.active = ob
    print("@@ edit mode starts", flush=True)
    with bpy.context.temp_override(**w.context()):
        bpy.ops.object.mode_set(mode="EDIT")
    yield SETTLE
    shot(w, "edit_mode")
    yield SETTLE
    with bpy.context.temp_override(**w.context()):
        bpy.ops.object.mode_set(mode="OBJECT")
    print("@@ edit mode ends", flush=True)
    yield SETTLE

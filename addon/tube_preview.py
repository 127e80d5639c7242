"""Live tube preview in the 3D viewport: objects with ``tessera.tubes.preview`` are drawn on the GPU.

Per object the curves are read and framed once (`kernels.tubes.tube_sections`) and uploaded as section
textures; they are rebuilt only when the object or its settings change (depsgraph and property updates).
Sides per tube are recomputed when the view changes (camera LOD); the anti-aliasing clamp runs in the
vertex shader every frame. Nothing is drawn or compiled in background mode.
"""

import bpy
import numpy as np

from ..kernels.camera import Camera
from ..kernels.errors import TesseraError
from ..kernels.tubes import lod_sides, tube_sections
from .tube_settings import kernel_settings
from .tube_sources import SOURCE_TYPES, read_lines
from .viewport import tag_view3d_redraw

_state = {"handler": None, "cache": {}, "errors": {}}


def settings_changed(ob):
    """Forget ``ob``'s uploaded data and redraw (property update callback)."""
    if isinstance(ob, bpy.types.Object):
        _state["cache"].pop(ob.name, None)
        _state["errors"].pop(ob.name, None)
    tag_view3d_redraw()


@bpy.app.handlers.persistent  # survive file loads
def _on_depsgraph(scene, depsgraph):
    cache = _state["cache"]
    if not cache:
        return
    for update in depsgraph.updates:
        obj = update.id.original if hasattr(update.id, "original") else update.id
        if isinstance(obj, bpy.types.Object) and obj.name in cache and update.is_updated_geometry:
            cache.pop(obj.name, None)
        elif isinstance(obj, (bpy.types.Curve, bpy.types.Mesh, bpy.types.Curves)):
            for name, entry in list(cache.items()):
                if entry["data"] == obj.name:
                    cache.pop(name, None)


def _entry(ob):
    """Cached GPU data for ``ob`` (built on first use), or None when it cannot be built (error remembered)."""
    from ..gpu_shaders.tube_preview import TubeDrawData

    cache = _state["cache"]
    if ob.name not in cache and ob.name not in _state["errors"]:
        s = ob.tessera.tubes
        try:
            lines, _ = read_lines(ob, s)
            prepared, frames = tube_sections(lines, kernel_settings(s, aa_clamp=False))
        except TesseraError as err:
            _state["errors"][ob.name] = str(err)
            return None
        cache[ob.name] = {"data": ob.data.name, "lines": prepared, "view": None,
                          "draw": TubeDrawData(prepared, frames["n"], frames["b"], frames["radius"])}
    return cache.get(ob.name)


def _draw():
    import gpu

    context = bpy.context
    region, rv3d = context.region, context.region_data
    if region is None or rv3d is None:
        return
    view, proj = np.array(rv3d.view_matrix), np.array(rv3d.window_matrix)
    gpu.state.depth_test_set("LESS_EQUAL")
    gpu.state.depth_mask_set(True)
    for ob in context.visible_objects:
        if ob.type not in SOURCE_TYPES or not ob.tessera.tubes.preview:
            continue
        entry = _entry(ob)
        if entry is None:
            continue
        s = ob.tessera.tubes
        model = np.array(ob.matrix_world)
        key = (view @ model).tobytes() + proj.tobytes() + bytes((region.width % 256, region.height % 256))
        if entry["view"] != key:
            cam = Camera(view @ model, proj, region.width, region.height)
            entry["draw"].set_sides(lod_sides(entry["lines"], kernel_settings(s), cam))
            entry["view"] = key
        entry["draw"].draw(proj @ view @ model, region.width, clamp=s.aa_clamp, max_radius=s.max_radius)
    gpu.state.depth_test_set("NONE")
    gpu.state.depth_mask_set(False)


def register():
    bpy.app.handlers.depsgraph_update_post.append(_on_depsgraph)
    if not bpy.app.background:
        _state["handler"] = bpy.types.SpaceView3D.draw_handler_add(_draw, (), "WINDOW", "POST_VIEW")


def unregister():
    if _on_depsgraph in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(_on_depsgraph)
    if _state["handler"] is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_state["handler"], "WINDOW")
        _state["handler"] = None
    _state["cache"].clear()
    _state["errors"].clear()

"""Live tube preview in the 3D viewport: objects with ``tessera.tubes.preview`` are drawn on the GPU.

Per object the curves are read and framed once (`kernels.tubes.builder.tube_sections`) and uploaded as section
textures; they are rebuilt only when the object or its settings change (depsgraph and property updates).
Sides per tube are recomputed when the view changes (camera LOD); the anti-aliasing clamp runs in the
vertex shader every frame. Nothing is drawn or compiled in background mode.
"""

import bpy
import numpy as np

from ...kernels.common.camera import Camera
from ...kernels.common.errors import TesseraError
from ...kernels.tubes.builder import lod_sides, tube_sections
from ..viewport import add_handlers, drop_stale, new_state, remove_handlers, tag_view3d_redraw
from .settings import kernel_settings
from .sources import SOURCE_TYPES, read_lines

_state = new_state()


def settings_changed(ob):
    """Forget ``ob``'s uploaded data and redraw (property update callback)."""
    if isinstance(ob, bpy.types.Object):
        _state["cache"].pop(ob.name, None)
        _state["errors"].pop(ob.name, None)
    tag_view3d_redraw()


@bpy.app.handlers.persistent  # survive file loads
def _on_depsgraph(scene, depsgraph):
    drop_stale(_state, depsgraph, (bpy.types.Curve, bpy.types.Mesh, bpy.types.Curves))


def _entry(ob):
    """Cached GPU data for ``ob`` (built on first use), or None when it cannot be built (error remembered)."""
    from ...gpu_shaders.tubes.draw import TubeDrawData

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


def _draw(context, region, view, proj):
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


def register():
    add_handlers(_state, _draw, _on_depsgraph)


def unregister():
    remove_handlers(_state, _on_depsgraph)

"""Live tessellation preview in the 3D viewport: meshes with ``tessera.tessellate.preview`` are drawn tessellated
on the GPU (instanced patterns, `gpu_shaders.tessellation.draw`), with the object's own tessellation settings.

Per object the mesh is read once and its control texture uploaded; it is read again only when the mesh or
the surface settings change (depsgraph handler, settings key). Adaptive levels are recomputed only when the
view (or the object's transform) changes; uniform levels only when the settings do. A displacement map set on
the object (Tessera > Displacement) is sampled in the vertex shader, so brush strokes show live on the
tessellated surface. The preview is drawn even while the object is hidden, so the original can be hidden.
Nothing is drawn or compiled in background mode.
"""

import bpy
import numpy as np

from ...kernels.common.camera import Camera
from ...kernels.common.errors import TesseraError
from ...kernels.tessellation.adaptive import adaptive_levels
from ...kernels.tessellation.tessellate import surface_inputs, uniform_levels
from .. import bridge
from ..viewport import add_handlers, drop_stale, new_state, remove_handlers
from .settings import SETTING_NAMES, adaptive_settings, surface_options

_state = new_state()
#: Settings that change what is uploaded per mesh (the rest only change levels).
SURFACE_NAMES = ("method", "alpha", "alpha_attribute", "normal_mode", "pn_normals")


def _key(settings, names):
    return tuple(tuple(sorted(v)) if isinstance(v, set) else v for v in (getattr(settings, n) for n in names))


@bpy.app.handlers.persistent  # survive file loads
def _on_depsgraph(scene, depsgraph):
    drop_stale(_state, depsgraph, bpy.types.Mesh)


def forget(ob):
    """Drop ``ob``'s uploaded data (it is rebuilt on the next draw)."""
    _state["cache"].pop(ob.name, None)
    _state["errors"].pop(ob.name, None)


def _uv_name(ob):
    """The UV map the displacement uses (its own, else the active one), or None."""
    return ob.tessera.displacement.uv_map or getattr(ob.data.uv_layers.active, "name", None)


def _tangent_space(ob):
    d = ob.tessera.displacement
    return d.mode == "VECTOR" and d.space == "TANGENT"


def _surface_key(ob):
    """What the uploaded control data depends on: surface settings, the UV map, tangents or not."""
    return _key(ob.tessera.tessellate, SURFACE_NAMES) + (_uv_name(ob), _tangent_space(ob))


def entry_for(ob):
    """Cached GPU data for ``ob`` (built on first use), or None when it cannot be built (error remembered)."""
    from ...gpu_shaders.tessellation.draw import PatchDrawData

    s = ob.tessera.tessellate
    cache, surface = _state["cache"], _surface_key(ob)
    entry = cache.get(ob.name)
    if entry is not None and entry["surface"] != surface:
        forget(ob)
    if ob.name not in cache and ob.name not in _state["errors"]:
        try:
            arrays, _ = bridge.read_mesh(ob.data)
            method = s.method
            inputs = surface_inputs(arrays, uniform_levels(arrays, 1), method if method != "LINEAR" else "PN",
                                    surface_options(s))
            uv_name = _uv_name(ob)
            uvs = arrays.corner_attributes.get(uv_name) if uv_name else None
            tangents = bridge.corner_tangents(ob.data, uv_name) if uvs is not None and _tangent_space(ob) else None
            draw = PatchDrawData(inputs, method, s.alpha, s.pn_normals == "QUADRATIC", uvs=uvs, tangents=tangents)
        except TesseraError as err:
            _state["errors"][ob.name] = str(err)
            return None
        cache[ob.name] = {"data": ob.data.name, "surface": surface, "levels": None, "draw": draw}
    return cache.get(ob.name)


def update_levels(ob, entry, view, projection, width, height):
    """Recompute levels when the view, the transform or a level setting changed; returns True when it did."""
    s = ob.tessera.tessellate
    model = np.array(ob.matrix_world)
    key = _key(s, SETTING_NAMES)
    if s.level_mode == "ADAPTIVE":
        key += ((view @ model).tobytes(), np.asarray(projection).tobytes(), width, height)
    if entry["levels"] == key:
        return False
    draw = entry["draw"]
    mesh = draw.inputs.mesh
    if s.level_mode == "UNIFORM":
        edge, inner = uniform_levels(mesh, s.level), None
    else:
        world = mesh.positions.astype(np.float64) @ model[:3, :3].T + model[:3, 3]
        camera = Camera(view, projection, width, height)
        edge, inner = adaptive_levels(world, mesh.triangles, adaptive_settings(s), camera, mesh.corner_normals)
    draw.set_levels(edge, inner, s.spacing)
    entry["levels"] = key
    return True


def displacement_for(ob):
    """The object's displacement map as a preview `Displacement`, or None (no map, or world-space vectors,
    which the preview does not show). Tangent-space maps use the tangents uploaded with the mesh."""
    from ...gpu_shaders.tessellation.draw import Displacement

    d = ob.tessera.displacement
    if d.image is None or (d.mode == "VECTOR" and d.space == "GLOBAL"):
        return None
    import gpu

    mode = "TANGENT" if _tangent_space(ob) else d.mode
    return Displacement(gpu.texture.from_image(d.image), mode, d.mid_level, d.strength)


def _draw(context, region, view, proj):
    shading = context.space_data.shading.type if context.space_data else "SOLID"
    for ob in context.view_layer.objects:
        if ob.type != "MESH" or not ob.tessera.tessellate.preview:
            continue
        entry = entry_for(ob)
        if entry is None:
            continue
        update_levels(ob, entry, view, proj, region.width, region.height)
        vp = proj @ view @ np.array(ob.matrix_world)
        disp = displacement_for(ob)
        if shading != "WIREFRAME":
            entry["draw"].draw(vp, displacement=disp)
        if shading == "WIREFRAME" or context.space_data.overlay.show_wireframes:
            entry["draw"].draw(vp, color=(0.05, 0.05, 0.05, 1.0), lit=False, displacement=disp, wireframe=True)


def register():
    add_handlers(_state, _draw, _on_depsgraph)


def unregister():
    remove_handlers(_state, _on_depsgraph)

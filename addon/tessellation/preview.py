"""Live tessellation preview in the 3D viewport: meshes with ``tessera.tessellate.preview`` are drawn tessellated
on the GPU (instanced patterns, `gpu_shaders.tessellation.draw`), with the object's own tessellation settings.

Per object the mesh is read once and its control texture uploaded; it is read again only when the mesh or
the surface settings change (depsgraph handler, settings key). Adaptive levels are recomputed only when the
view (or the object's transform) changes; uniform levels only when the settings do. A displacement map set on
the object (Tessera > Displacement) is sampled in the vertex shader, so brush strokes show live on the
tessellated surface. The preview is drawn instead of the object (`viewport.sync_source`), from the object's
evaluated mesh (its modifiers applied, as *Tessellate* reads it; its own mesh while it samples the object's
displacement map, whose modifier would displace it twice); hiding the object hides it, as does Edit Mode.
Nothing is drawn or compiled in background mode.
"""

import bpy
import numpy as np

from ...kernels.common.camera import Camera
from ...kernels.tessellation.adaptive import adaptive_levels
from ...kernels.tessellation.tessellate import surface_inputs, uniform_levels
from .. import bridge
from ..settings_scaffold import option_names
from ..viewport import Preview, PreviewEntry, previewed_objects, source_mesh
from ..viewport_lighting import draw_as_object
from .settings import TOPIC, TessellateOptions, adaptive_settings, surface_options

#: Settings that change what is uploaded per mesh (the rest only change levels).
SURFACE_NAMES = ("method", "alpha", "alpha_attribute", "normal_mode", "pn_normals")


def _key(settings, names):
    return tuple(tuple(sorted(v)) if isinstance(v, set) else v for v in (getattr(settings, n) for n in names))


def _uv_name(ob):
    """The UV map the displacement uses (its own, else the active one), or None."""
    return ob.tessera.displacement.uv_map or getattr(ob.data.uv_layers.active, "name", None)


def _tangent_space(ob):
    d = ob.tessera.displacement
    return d.mode == "VECTOR" and d.space == "TANGENT"


def _samples_map(ob):
    """The preview displaces by the object's map itself (`displacement_for`)."""
    d = ob.tessera.displacement
    return d.image is not None and not (d.mode == "VECTOR" and d.space == "GLOBAL")


def _surface_key(ob):
    """What the uploaded control data depends on: surface settings, the UV map, tangents or not, the map sampled."""
    return _key(ob.tessera.tessellate, SURFACE_NAMES) + (_uv_name(ob), _tangent_space(ob), _samples_map(ob))


def entry_for(ob):
    """Cached GPU data for ``ob`` (built on first use), or None when it cannot be built (error remembered)."""
    surface = _surface_key(ob)
    entry = PREVIEW.cache.get(ob)
    if entry is not None and entry.source != surface:
        PREVIEW.cache.forget(ob)

    def build():
        from ...gpu_shaders.tessellation.draw import PatchDrawData

        s = ob.tessera.tessellate
        if _samples_map(ob):  # the map's own modifier would displace a second time: the undisplaced mesh
            mesh, release = ob.data, (lambda: None)
        else:
            mesh, release = source_mesh(ob, bpy.context.evaluated_depsgraph_get())
        try:
            arrays, _ = bridge.read_mesh(mesh)
            uv_name = _uv_name(ob)
            uvs = arrays.corner_attributes.get(uv_name) if uv_name else None
            tangents = bridge.corner_tangents(mesh, uv_name) if uvs is not None and _tangent_space(ob) else None
        finally:
            release()
        method = s.method
        inputs = surface_inputs(arrays, uniform_levels(arrays, 1), method if method != "LINEAR" else "PN",
                                surface_options(s))
        draw = PatchDrawData(inputs, method, s.alpha, s.pn_normals == "QUADRATIC", uvs=uvs, tangents=tangents)
        return PreviewEntry(draw, data_uid=ob.data.session_uid, source=surface)

    return PREVIEW.entry(ob, build)


def update_levels(ob, entry, view, projection, width, height):
    """Recompute levels when the view, the transform or a level setting changed; returns True when it did."""
    s = ob.tessera.tessellate
    model = np.array(ob.matrix_world)
    key = _key(s, option_names(TessellateOptions))
    if s.level_mode == "ADAPTIVE":
        key += ((view @ model).tobytes(), np.asarray(projection).tobytes(), width, height)
    if entry.view == key:
        return False
    draw = entry.draw
    mesh = draw.inputs.mesh
    if s.level_mode == "UNIFORM":
        edge, inner = uniform_levels(mesh, s.level), None
    else:
        world = mesh.positions.astype(np.float64) @ model[:3, :3].T + model[:3, 3]
        camera = Camera(view, projection, width, height)
        edge, inner = adaptive_levels(world, mesh.triangles, adaptive_settings(s), camera, mesh.corner_normals)
    draw.set_levels(edge, inner, s.spacing)
    entry.view = key
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


def previewing(ob):
    """The preview is on for ``ob``."""
    return ob.type == "MESH" and ob.tessera.tessellate.preview


def _draw(context, region, view, proj):
    for ob in previewed_objects(context, previewing):
        entry = entry_for(ob)
        if entry is None:
            continue
        update_levels(ob, entry, view, proj, region.width, region.height)
        vp = proj @ view @ np.array(ob.matrix_world)
        draw_as_object(context, ob, view, entry.draw.draw, vp, wire=True, displacement=displacement_for(ob))


def _settings_changed(ob):
    """Uploads are keyed on the settings they depend on (`entry_for`); a change only lets a failed object retry."""
    if isinstance(ob, bpy.types.Object):
        PREVIEW.cache.forget_error(ob)


PREVIEW = Preview(_draw, data_types=(bpy.types.Mesh,), topic=TOPIC, on_settings=_settings_changed,
                  replaces=previewing)
register, unregister = PREVIEW.register, PREVIEW.unregister

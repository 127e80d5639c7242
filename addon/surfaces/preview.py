"""Live one-point surfaces in the 3D viewport: objects with ``tessera.surface.is_surface`` (empties made by *Add ›
Tessera › Parametric Surface* with Output Live) are drawn on the GPU, one instance of the quad-domain pattern per
control point (the object's origin, or the vertices of its Control Points mesh), the formula evaluated in the
vertex shader. The control points are uploaded once, and again when either object moves, the control mesh is edited
or a setting changes; with Factor From Camera each instance's factor follows the view. It is drawn as the
viewport draws objects (lit as Solid mode lights them, hidden with the empty). Nothing is drawn in background mode."""

import bpy
import numpy as np

from ...kernels.common.camera import Camera
from ..viewport import Preview, PreviewEntry, previewed_objects
from ..viewport_lighting import draw_as_object
from .settings import TOPIC, surface_from
from .sources import control_points, instance_factors


def _placement(ob):
    """What the control points in ``ob``'s space depend on besides the control mesh: both objects' transforms."""
    src = ob.tessera.surface.instance_object
    key = np.array(ob.matrix_world).tobytes()
    return key + (np.array(src.matrix_world).tobytes() if src is not None else b"")


def entry_for(ob, camera=None):
    """The live surface's draw data for ``camera`` (its factors), or None when it cannot be built. Rebuilt when the
    control mesh is edited, a setting changes, or either object moves."""
    from ...gpu_shaders.surfaces.draw import SurfaceDrawData

    src = ob.tessera.surface.instance_object
    placement = _placement(ob)
    cached = PREVIEW.cache.get(ob)
    if cached is not None and cached.source[1] != placement:
        PREVIEW.cache.forget(ob)
    entry = PREVIEW.entry(ob, lambda: PreviewEntry(None, data_uid=src.data.session_uid if src else None,
                                                   source=(control_points(ob), placement)))
    if entry is None:
        return None
    points = entry.source[0]
    factors = instance_factors(ob, points, camera)
    key = factors.tobytes()
    if entry.view != key:
        entry.draw, entry.view = SurfaceDrawData(surface_from(ob.tessera.surface), points, factors), key
    return entry


def _draw(context, region, view, proj):
    for ob in previewed_objects(context, lambda ob: ob.tessera.surface.is_surface):
        model = np.array(ob.matrix_world)
        entry = entry_for(ob, Camera(view @ model, proj, region.width, region.height))
        if entry is None:
            continue
        draw_as_object(context, ob, view, entry.draw.draw, proj @ view @ model, wire=True)


PREVIEW = Preview(_draw, data_types=(bpy.types.Mesh,), topic=TOPIC)
register, unregister = PREVIEW.register, PREVIEW.unregister

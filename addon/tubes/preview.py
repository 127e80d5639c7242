"""Live tube preview in the 3D viewport: objects with ``tessera.tubes.preview`` are drawn on the GPU.

Per object the curves are read and framed once (`kernels.tubes.builder.tube_sections`) and uploaded as section
textures; they are rebuilt only when the object or its settings change (depsgraph and the "tubes" settings
topic). Sides per tube are recomputed when the view changes (camera LOD); the anti-aliasing clamp runs in the
vertex shader every frame. It is drawn as the viewport draws objects (lit as Solid mode lights them, hidden with
its source). Nothing is drawn or compiled in background mode.
"""

import bpy
import numpy as np

from ...kernels.common.camera import Camera
from ...kernels.tubes.builder import lod_sides, tube_sections
from ..viewport import Preview, PreviewEntry, previewed_objects
from ..viewport_lighting import draw_as_object
from .settings import TOPIC, kernel_settings
from .sources import SOURCE_TYPES, read_lines


def entry_for(ob):
    """Cached GPU data for ``ob`` (built on first use), or None when it cannot be built (error remembered)."""

    def build():
        from ...gpu_shaders.tubes.draw import TubeDrawData

        s = ob.tessera.tubes
        lines, _ = read_lines(ob, s)
        prepared, frames = tube_sections(lines, kernel_settings(s, aa_clamp=False))
        return PreviewEntry(TubeDrawData(prepared, frames.n, frames.b, frames.radius), data_uid=ob.data.session_uid)

    return PREVIEW.entry(ob, build)


def previewing(ob):
    """The preview is on for ``ob`` (a curve, hair or wire mesh)."""
    return ob.type in SOURCE_TYPES and ob.tessera.tubes.preview


def _draw(context, region, view, proj):
    for ob in previewed_objects(context, previewing):
        entry = entry_for(ob)
        if entry is None:
            continue
        s = ob.tessera.tubes
        model = np.array(ob.matrix_world)
        key = (view @ model).tobytes() + proj.tobytes() + bytes((region.width % 256, region.height % 256))
        if entry.view != key:
            cam = Camera(view @ model, proj, region.width, region.height)
            entry.draw.set_sides(lod_sides(entry.draw.lines, kernel_settings(s), cam))
            entry.view = key
        draw_as_object(context, ob, view, entry.draw.draw, proj @ view @ model, region.width, wire=True,
                       clamp=s.aa_clamp, max_radius=s.max_radius)


PREVIEW = Preview(_draw, data_types=(bpy.types.Curve, bpy.types.Mesh, bpy.types.Curves), topic=TOPIC)
register, unregister = PREVIEW.register, PREVIEW.unregister

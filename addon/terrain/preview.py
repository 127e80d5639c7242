"""Live terrain preview in the 3D viewport: terrain objects with ``tessera.terrain.preview`` are drawn on the GPU.

The height map is uploaded once per object (until its source settings change); levels are selected again
only when the view changes (numpy, a few milliseconds for 65k tiles), and only the tile table of the new
selection is uploaded. The preview is drawn instead of the terrain object's baked mesh (`viewport.sync_source`) and
lit as Solid mode lights objects; hiding the object hides it, as does Edit Mode. Nothing is drawn or compiled in
background mode.
"""

import bpy
import numpy as np

from ...kernels.common.camera import Camera
from ...kernels.terrain.lod import select
from ..viewport import Preview, PreviewEntry, previewed_objects
from ..viewport_lighting import draw_as_object
from . import data as terrain_data
from .settings import TOPIC, lod_settings, source_key


def settings_changed(ob):
    """Forget ``ob``'s selection (and its upload when the source changed); the "terrain" topic's subscriber."""
    if not isinstance(ob, bpy.types.Object):
        return
    entry = PREVIEW.cache.get(ob)
    if entry is not None and entry.source == source_key(ob.tessera.terrain):
        entry.view = None
        PREVIEW.cache.forget_error(ob)
    else:
        PREVIEW.cache.forget(ob)


def entry_for(ob):
    """Cached GPU data for ``ob`` (built on first use), or None when it cannot be built (error remembered)."""

    def build():
        from ...gpu_shaders.terrain.draw import TerrainDrawData

        hm, table = terrain_data.analysis(ob)
        return PreviewEntry(TerrainDrawData(hm, table), source=source_key(ob.tessera.terrain))

    return PREVIEW.entry(ob, build)


def update_view(ob, entry, view, projection, width, height):
    """Re-select levels when the view (or a setting) changed; returns True when it did."""
    model = np.array(ob.matrix_world)
    key = (view @ model).tobytes() + np.asarray(projection).tobytes() + bytes((width % 256, height % 256))
    if entry.view == key:
        return False
    draw = entry.draw
    camera = Camera(view @ model, projection, width, height)
    draw.set_selection(select(draw.hm, draw.table, camera, lod_settings(ob.tessera.terrain)))
    entry.view = key
    return True


def previewing(ob):
    """The preview is on for terrain object ``ob``."""
    s = ob.tessera.terrain
    return s.is_terrain and s.preview


def _draw(context, region, view, proj):
    for ob in previewed_objects(context, previewing):
        entry = entry_for(ob)
        if entry is None:
            continue
        update_view(ob, entry, view, proj, region.width, region.height)
        draw_as_object(context, ob, view, entry.draw.draw, proj @ view @ np.array(ob.matrix_world), wire=True)


PREVIEW = Preview(_draw, topic=TOPIC, on_settings=settings_changed, replaces=previewing)


def register():
    PREVIEW.register()


def unregister():
    PREVIEW.unregister()
    terrain_data.forget()

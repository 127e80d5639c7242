"""Live Loop preview in the 3D viewport: meshes with ``tessera.loop.preview`` are drawn Loop-subdivided, lit as
Solid mode lights objects (their baked colours where the viewport's Color is Attribute), from the kernel's result
(uploaded once; rebuilt when the mesh or the settings change), instead of the object itself
(`viewport.sync_source`); like *Loop Subdivision*, it reads the object's own mesh. Nothing is drawn or compiled in
background mode."""

import bpy
import numpy as np

from ...kernels.common.normals import shared_vertex_normals
from ..bridge import read_edge_marks, read_mesh
from ..preferences import get_preferences
from ..viewport import Preview, PreviewEntry, previewed_objects
from ..viewport_lighting import draw_as_object
from .build import HCE_PROPERTY, subdivide
from .settings import TOPIC


def build_draw_data(ob, budget_bytes=0):
    """The `gpu_shaders.subdivision.draw.LoopDrawData` of ``ob``'s mesh with its ``tessera.loop`` settings."""
    from ...gpu_shaders.subdivision.draw import LoopDrawData

    arrays, _ = read_mesh(ob.data)
    build = subdivide(arrays, read_edge_marks(ob.data), ob.tessera.loop, ob.data.get(HCE_PROPERTY), budget_bytes)
    r = build.result
    return LoopDrawData(r.positions, shared_vertex_normals(r.positions, r.triangles), build.baked, r.triangles)


def entry_for(ob):
    """Cached draw data for ``ob`` (built on first use), or None when it cannot be built (error remembered)."""
    return PREVIEW.entry(ob, lambda: PreviewEntry(build_draw_data(ob, get_preferences().memory_budget_bytes),
                                                  data_uid=ob.data.session_uid))


def previewing(ob):
    """The preview is on for ``ob``."""
    return ob.type == "MESH" and ob.tessera.loop.preview


def _draw(context, region, view, proj):
    colour_type = context.space_data.shading.color_type
    for ob in previewed_objects(context, previewing):
        entry = entry_for(ob)
        if entry is None:
            continue
        # Color: Attribute shows the baked colours, as it shows the applied mesh's; lit as every object is
        draw_as_object(context, ob, view, entry.draw.draw, proj @ view @ np.array(ob.matrix_world), wire=True,
                       vertex_colors=entry.draw.baked and colour_type == "VERTEX")


PREVIEW = Preview(_draw, data_types=(bpy.types.Mesh,), topic=TOPIC, replaces=previewing)
register, unregister = PREVIEW.register, PREVIEW.unregister

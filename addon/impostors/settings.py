"""Live nailboard settings: ``Object.tessera.nailboard`` (Sidebar › Tessera › Impostors)."""

import bpy

from ..viewport import invalidator

#: The invalidation topic of these settings (`addon.viewport`).
TOPIC = "impostors"
_changed = invalidator(TOPIC)


class TESSERA_PG_impostors(bpy.types.PropertyGroup):
    enabled: bpy.props.BoolProperty(
        name="Live Nailboard", default=False, update=_changed,
        description="Draw this object in the viewport from a board rendered by Cycles in a background process "
                    "(colour, depth and normals) instead of its geometry, regenerated when the view makes it invalid")
    relief: bpy.props.BoolProperty(name="Relief Mapping", default=True, update=_changed,
                                   description="Pre-warp the board for the eye (parallax corrected, per-texel "
                                               "depth); off: a plain sprite, regenerated sooner")
    tolerance: bpy.props.FloatProperty(name="Screen Error", default=1.5, min=0.1, max=100.0, soft_max=16.0,
                                       subtype="PIXEL", update=_changed,
                                       description="How many screen pixels a board texel or its error may grow to "
                                                   "before the board is made again")
    samples: bpy.props.IntProperty(name="Samples", default=16, min=1, max=4096, soft_max=1024, update=_changed,
                                   description="Cycles samples per board")
    progressive: bpy.props.BoolProperty(
        name="Preview First", default=True, update=_changed,
        description="From 8 samples, render a quick board with a sixteenth of the samples first and draw it until "
                    "the full render is there")
    lead: bpy.props.IntProperty(name="Prediction", default=4, min=0, max=120, update=_changed,
                                description="Ask for the board the camera will need this many frames ahead")


classes = (TESSERA_PG_impostors,)
register, unregister = bpy.utils.register_classes_factory(classes)

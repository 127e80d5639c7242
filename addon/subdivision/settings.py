"""Loop subdivision settings: one set of properties shared by ``tessera.loop_subdivide`` (redo panel) and
``Object.tessera.loop`` (the viewport preview)."""

import bpy

from ...kernels.subdivision.loop import MAX_LEVELS
from ..settings_scaffold import option_names, stored_options
from ..viewport import invalidator

BOUNDARY_ITEMS = (
    ("EDGE_ONLY", "Smooth", "Open borders are smoothed along the border, like a curve through its vertices"),
    ("EDGE_AND_CORNER", "Keep Corners",
     "As Smooth, and border vertices with a single face (the corners of a plane) stay where they are"),
)
BAKED_COLOUR = "BakedLight"  # the point colour attribute written from the mesh's baked lighting


class LoopOptions:
    """The Loop options, declared once: the operator inherits them as they are, `TESSERA_PG_subdivision` with the
    preview's invalidation added (`addon.settings_scaffold`)."""

    levels: bpy.props.IntProperty(
        name="Levels", description="Times every triangle is split in four (faces grow by 4^levels; 0: the "
        "triangulated mesh as it is, with its baked lighting)", default=2, min=0, max=MAX_LEVELS, soft_max=4)
    boundary: bpy.props.EnumProperty(name="Boundary", items=BOUNDARY_ITEMS, default="EDGE_ONLY",
                                     description="What happens at the open borders of the mesh")
    use_creases: bpy.props.BoolProperty(
        name="Creases", default=True,
        description="Edges marked sharp and edges with crease 1 stay sharp; smaller creases soften over the "
                    "levels, as in Blender's Subdivision Surface; vertex creases make corners")
    use_baked_lighting: bpy.props.BoolProperty(
        name="Baked Lighting", default=True,
        description=f"Where the mesh has lighting baked by Bake Lighting, write it at the new level as the "
                    f"colour attribute {BAKED_COLOUR!r}")


#: The invalidation topic of these settings (`addon.viewport`).
TOPIC = "subdivision"
_changed = invalidator(TOPIC)


class TESSERA_PG_subdivision(bpy.types.PropertyGroup):
    __annotations__ = stored_options(LoopOptions, _changed, preview=bpy.props.BoolProperty(
        name="Preview Loop Subdivision", update=_changed, default=False,
        description="Draw this mesh Loop-subdivided in the 3D viewport, with its baked lighting (no mesh is made)"))


def draw_subdivision_settings(layout, s):
    layout.use_property_split = True
    layout.use_property_decorate = False
    col = layout.column()
    for name in option_names(LoopOptions):
        col.prop(s, name)


classes = (TESSERA_PG_subdivision,)
register, unregister = bpy.utils.register_classes_factory(classes)

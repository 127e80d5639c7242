"""Displacement-map settings: the map bound to an object (``Object.tessera.displacement``) and the brush
(``Scene.tessera.brush``, shared by the brush tool and stroke replays). ``Image.tessera.serial`` counts the strokes
applied to a map image; undo and redo restore the map to the serial that Blender's undo step holds."""

import bpy

from ...kernels.common.limits import MAX_FACTOR, MAX_PIXELS, MAX_WORLD_VALUE
from ...kernels.displacement.map_dabs import FALLOFFS
from .maps import sync_modifier

MODE_ITEMS = (
    ("HEIGHT", "Height", "One value per texel, displaced along the normal"),
    ("VECTOR", "Vector", "An XYZ offset per texel (object, world or tangent space)"),
)
# object and world space are shown by Blender's Displace modifier, tangent space by a geometry-nodes group
SPACE_ITEMS = (
    ("LOCAL", "Object", "X, Y, Z in the object's own axes"),
    ("GLOBAL", "World", "X, Y, Z in world axes"),
    ("TANGENT", "Tangent", "X along the UV map's U tangent, Y along the bitangent, Z along the normal "
                           "(the tangent space of baked normal maps; Blender 5.0 and newer)"),
)
BRUSH_ITEMS = (
    ("DRAW", "Draw", "Raise (or lower, with negative strength) along the brush direction with a falloff"),
    ("SMOOTH", "Smooth", "Move texels toward the mean of their neighbours"),
    ("FLATTEN", "Flatten", "Move texels toward the mean height under the brush"),
    ("NOISE", "Noise", "Add value noise anchored to the map"),
    ("CONTACT", "Contact", "Press a hard-edged disc in by Strength (Z only)"),
    ("FORCE", "Force", "Push in a cone of depth Strength as wide as the brush"),
    ("TEST", "Offset Disc", "Add the brush direction times Strength inside a hard-edged disc"),
)
def map_value_property(name, default, description):
    """A map value for 8- and 16-bit files (what black or white stands for): a float property, any finite value."""
    return bpy.props.FloatProperty(name=name, default=default, min=-MAX_WORLD_VALUE, max=MAX_WORLD_VALUE,
                                   soft_min=-100.0, soft_max=100.0, description=description)


FALLOFF_ITEMS = tuple((f, f.title(), f"{f.title()} falloff curve, as in Blender's brushes") for f in FALLOFFS)


def _sync_modifier(self, context):
    ob = self.id_data
    if isinstance(ob, bpy.types.Object):
        sync_modifier(ob)


class TESSERA_PG_displacement(bpy.types.PropertyGroup):
    image: bpy.props.PointerProperty(name="Map", type=bpy.types.Image, description="Float image with the map",
                                     update=_sync_modifier)
    mode: bpy.props.EnumProperty(name="Mode", items=MODE_ITEMS, default="HEIGHT", update=_sync_modifier,
                                 description="One height per texel, or an XYZ offset per texel")
    space: bpy.props.EnumProperty(name="Space", items=SPACE_ITEMS, default="LOCAL", update=_sync_modifier,
                                  description="The axes a vector map's X, Y and Z follow")
    uv_map: bpy.props.StringProperty(name="UV Map", description="UV map that places the map (empty: active)",
                                     update=_sync_modifier)
    mid_level: bpy.props.FloatProperty(name="Mid-Level", default=0.0, soft_min=0.0, soft_max=1.0,
                                       min=-MAX_WORLD_VALUE, max=MAX_WORLD_VALUE,
                                       description="The map value that means no displacement", update=_sync_modifier)
    strength: bpy.props.FloatProperty(name="Strength", default=1.0, soft_min=-10.0, soft_max=10.0, min=-MAX_FACTOR,
                                      max=MAX_FACTOR,
                                      description="Displacement per unit of map value", update=_sync_modifier)
    kernel_text: bpy.props.PointerProperty(name="Custom Kernel", type=bpy.types.Text,
                                           description="Text with an OpenCL body that edits `float4 image` at (x, y)")
    kernel_args: bpy.props.FloatVectorProperty(name="Arguments", size=16, default=(0.0,) * 16, min=-MAX_WORLD_VALUE,
                                               max=MAX_WORLD_VALUE, soft_min=-1000.0, soft_max=1000.0,
                                               description="The custom kernel's four arguments arg1 to arg4, four "
                                                           "numbers each")


class TESSERA_PG_brush(bpy.types.PropertyGroup):
    kind: bpy.props.EnumProperty(name="Brush", items=BRUSH_ITEMS, default="DRAW",
                                 description="What a dab does to the map")
    radius: bpy.props.FloatProperty(name="Radius", default=24.0, min=0.5, max=MAX_PIXELS, soft_max=512.0,
                                    subtype="PIXEL",
                                    description="Brush radius in map texels")
    strength: bpy.props.FloatProperty(name="Strength", default=0.05, soft_min=-1.0, soft_max=1.0, min=-MAX_FACTOR,
                                      max=MAX_FACTOR,
                                      description="Change per dab (map units; smooth and flatten: the blend)")
    falloff: bpy.props.EnumProperty(name="Falloff", items=FALLOFF_ITEMS, default="SMOOTH",
                                    description="How a dab fades from its centre to its edge")
    spacing: bpy.props.FloatProperty(name="Spacing", default=0.25, min=0.01, max=4.0, subtype="FACTOR",
                                     description="Distance between dabs, as a fraction of the radius")
    use_pressure_strength: bpy.props.BoolProperty(name="Pressure Strength", default=True,
                                                  description="Tablet pressure scales the strength")
    use_pressure_radius: bpy.props.BoolProperty(name="Pressure Radius", default=False,
                                                description="Tablet pressure scales the radius")
    mirror_x: bpy.props.BoolProperty(name="X Mirror", default=False,
                                     description="Mirror dabs across the map's vertical centre line (U = 0.5)")
    direction: bpy.props.FloatVectorProperty(name="Direction", size=3, default=(0.0, 0.0, 1.0), min=-MAX_FACTOR,
                                             max=MAX_FACTOR, soft_min=-10.0, soft_max=10.0, subtype="XYZ",
                                             description="Vector maps: the offset direction (height maps use Z)")
    noise_cell: bpy.props.FloatProperty(name="Noise Size", default=8.0, min=0.5, max=MAX_PIXELS, soft_max=256.0,
                                        subtype="PIXEL", description="Size of the noise's features, in map texels")
    noise_seed: bpy.props.IntProperty(name="Seed", default=0, min=0, soft_max=10000,
                                      description="Another seed gives another noise pattern")


class TESSERA_PG_image(bpy.types.PropertyGroup):
    """``Image.tessera``: the strokes applied to a map image (undo and redo restore the map to this serial)."""

    serial: bpy.props.IntProperty(name="Stroke Serial", default=0, options={"HIDDEN"})


classes = (TESSERA_PG_displacement, TESSERA_PG_brush, TESSERA_PG_image)
register, unregister = bpy.utils.register_classes_factory(classes)

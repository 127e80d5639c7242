"""The options of *Vector Field Texture* (`FieldOptions`) and how its redo panel shows them."""

import math

import bpy

from ...kernels.common.limits import MAX_WORLD_VALUE

FIELD_ITEMS = (
    ("ABC", "ABC Flow", "A classic swirling 3-D flow, seen on one slice"),
    ("VORTEX", "Vortex", "A smooth vortex round the centre"),
    ("MESH", "Grid Mesh", "Vectors of a point attribute on a grid mesh object (its x and y, over its area)"),
)
BACKEND_ITEMS = (
    ("AUTO", "Auto", "The GPU where Blender can use one, else the CPU"),
    ("GPU", "GPU", "The GPU (an error where Blender cannot use one)"),
    ("CPU", "CPU", "The CPU"),
)


class FieldOptions:
    """The options of ``tessera.vector_field_texture``."""

    field: bpy.props.EnumProperty(name="Field", items=FIELD_ITEMS, default="ABC",
                                  description="The flow the texture follows")
    field_object: bpy.props.StringProperty(name="Grid Object", description="Mesh object whose grid holds the field")
    attribute: bpy.props.StringProperty(name="Attribute", default="velocity",
                                        description="Vector point attribute of the grid holding the field")
    slice_z: bpy.props.FloatProperty(name="Slice", default=0.0, min=-MAX_WORLD_VALUE, max=MAX_WORLD_VALUE,
                                     soft_min=0.0, soft_max=2.0 * math.pi, subtype="ANGLE",
                                     description="Where the ABC flow is sliced (it repeats every full turn)")
    speed: bpy.props.FloatProperty(name="Speed", default=1.0, min=-1e6, max=1e6, soft_min=-10.0, soft_max=10.0,
                                   description="Multiplies the field's vectors: how far the streaks reach")
    width: bpy.props.IntProperty(name="Width", default=512, min=8, max=8192, subtype="PIXEL",
                                 description="Width of the texture")
    height: bpy.props.IntProperty(name="Height", default=512, min=8, max=8192, subtype="PIXEL",
                                  description="Height of the texture")
    seeds: bpy.props.IntProperty(name="Seeds", default=128, min=1, max=4096, soft_max=1024,
                                 description="Streak starting points per side when the camera is far (up to 4 times "
                                             "more when near)")
    near: bpy.props.FloatProperty(name="Near", default=2.0, min=0.0, max=MAX_WORLD_VALUE, soft_max=1000.0,
                                  subtype="DISTANCE", unit="LENGTH",
                                  description="Camera distance at and below which the streaks are densest")
    far: bpy.props.FloatProperty(name="Far", default=20.0, min=1e-4, max=MAX_WORLD_VALUE, soft_max=1000.0,
                                 subtype="DISTANCE", unit="LENGTH",
                                 description="Camera distance at and beyond which the streaks are sparsest")
    step: bpy.props.FloatProperty(name="Step", default=0.002, min=1e-6, max=1.0, soft_max=0.05, precision=4,
                                  description="How far a streak moves per step, as a fraction of the texture's width")
    steps: bpy.props.IntProperty(name="Steps", default=40, min=1, max=10000, soft_max=500,
                                 description="Steps per streak: its length is Steps × Step")
    noise_seed: bpy.props.IntProperty(name="Noise Seed", default=0, min=0, max=2**31 - 1, soft_max=10000,
                                      description="Another seed gives another pattern of streaks")
    backend: bpy.props.EnumProperty(name="Evaluate On", items=BACKEND_ITEMS, default="AUTO",
                                    description="Where the texture is computed")

def draw_field_options(layout, options):
    layout.use_property_split = True
    layout.use_property_decorate = False
    col = layout.column()
    col.prop(options, "field")
    if options.field == "MESH":
        col.prop_search(options, "field_object", bpy.data, "objects")
        col.prop(options, "attribute")
    elif options.field == "ABC":
        col.prop(options, "slice_z")
    col.prop(options, "speed")
    for name in ("width", "height", "seeds", "near", "far", "step", "steps", "noise_seed", "backend"):
        col.prop(options, name)

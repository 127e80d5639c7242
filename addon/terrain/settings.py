"""Terrain settings: one set of properties shared by ``tessera.terrain_add`` (redo panel) and
``Object.tessera.terrain`` (bake, preview and batch re-runs). `lod_settings` turns them into
`kernels.terrain.lod.TerrainLod`; `source_key` says when the height map must be read and analysed again."""

import bpy

from ...kernels.common.limits import MAX_FACTOR, MAX_PIXELS, MAX_WORLD_VALUE
from ...kernels.terrain.lod import TerrainLod
from ..cameras import CAMERA_ITEMS
from ..viewport import invalidator, with_update

SOURCE_ITEMS = (
    ("FILE", "File", "PNG/TIFF (8 or 16 bit), EXR/TIFF (float) or raw r16/r32 read with OpenImageIO"),
    ("IMAGE", "Image", "A Blender image (its first channel)"),
)
MODE_ITEMS = (
    ("OURS", "Adaptive", "Edge levels between T_min (screen-space error) and T_max (height acceleration)"),
    ("DISTANCE", "Distance Only", "The distance law without T_max (refines flat ground too)"),
    ("UNIFORM", "Uniform", "Maximum level everywhere (one quad per texel at level 64)"),
)
G_ITEMS = (
    ("SQRT", "Square Root", "T_max = k·sqrt(HAM max)"),
    ("LOG", "Logarithm", "T_max = 1 + k·log2(1 + HAM max)"),
)
T_MIN_ITEMS = (
    ("SEARCH", "Search", "Smallest power of two that brings each tile's peak within the error (seed Fig. 5.4)"),
    ("LOG2", "log2(ĥ/ε)", "The corrected closed form"),
    ("PRINTED", "log2(ε/ĥ) (as printed)", "Eq. 5-4 exactly as printed (it never refines: for comparison)"),
)
LEVEL_ITEMS = (
    ("POW2", "Powers of Two", "Vertices land on texels and stay put as levels change (no 'wave')"),
    ("INTEGER", "Integer", "Whole levels"),
    ("FRACTIONAL", "Fractional", "Continuous levels (fractional-even spacing): no popping while the camera moves"),
)


class TerrainOptions:
    """The terrain options, declared once: ``tessera.terrain_add`` inherits them as they are, and
    `TESSERA_PG_terrain` (``Object.tessera.terrain``) takes them with the preview's invalidation added
    (`with_update`)."""

    source: bpy.props.EnumProperty(name="Source", items=SOURCE_ITEMS, default="FILE")
    filepath: bpy.props.StringProperty(name="Height Map", subtype="FILE_PATH")
    image_name: bpy.props.StringProperty(name="Image", description="Blender image with the heights")
    raw_width: bpy.props.IntProperty(name="Raw Width", default=0, min=0, description="Samples per row (raw files)")
    raw_height: bpy.props.IntProperty(name="Raw Height", default=0, min=0, description="Rows (raw files)")
    texel_size: bpy.props.FloatProperty(name="Texel Size", default=1.0, min=1e-6, max=MAX_WORLD_VALUE,
                                        subtype="DISTANCE",
                                        description="Distance between neighbouring samples")
    height_scale: bpy.props.FloatProperty(name="Height Scale", default=100.0, min=-MAX_WORLD_VALUE,
                                          max=MAX_WORLD_VALUE, subtype="DISTANCE",
                                          description="Height of a full-scale integer sample (255 or 65535); "
                                          "the factor on float samples")
    height_offset: bpy.props.FloatProperty(name="Height Offset", default=0.0, min=-MAX_WORLD_VALUE,
                                           max=MAX_WORLD_VALUE, subtype="DISTANCE")
    tile_size: bpy.props.IntProperty(name="Tile Size", default=64, min=2, max=1024,
                                     description="Texels per tile side (64: one quad per texel at level 64)")
    mode: bpy.props.EnumProperty(name="Level Mode", items=MODE_ITEMS, default="OURS")
    g: bpy.props.EnumProperty(name="T_max From HAM", items=G_ITEMS, default="SQRT")
    ham_scale: bpy.props.FloatProperty(name="HAM Scale", default=4.0, min=1e-3, max=MAX_FACTOR, soft_max=64.0,
                                       description="k in the T_max function")
    epsilon: bpy.props.FloatProperty(name="Error (px)", default=3.0, min=0.05, max=MAX_PIXELS, soft_max=32.0,
                                     description="Allowed screen-space error of a tile's peak")
    t_min_rule: bpy.props.EnumProperty(name="T_min Rule", items=T_MIN_ITEMS, default="SEARCH")
    d_max: bpy.props.FloatProperty(name="Full-Detail Distance", default=0.0, min=0.0, max=MAX_WORLD_VALUE,
                                   subtype="DISTANCE",
                                   description="Below this distance tiles get T_max (0: where a texel spans "
                                   "4 pixels)")
    levels: bpy.props.EnumProperty(name="Levels", items=LEVEL_ITEMS, default="POW2")
    culling: bpy.props.BoolProperty(name="Frustum Culling", default=True,
                                    description="Drop tiles outside the camera's view")
    camera_source: bpy.props.EnumProperty(name="Camera", items=CAMERA_ITEMS, default="SCENE")


#: The invalidation topic of these settings (`addon.viewport`): the preview forgets what a change makes stale.
TOPIC = "terrain"
_changed = invalidator(TOPIC)
TERRAIN_SETTING_NAMES = tuple(TerrainOptions.__annotations__)
SOURCE_NAMES = ("source", "filepath", "image_name", "raw_width", "raw_height", "texel_size", "height_scale",
                "height_offset", "tile_size")


class TESSERA_PG_terrain(bpy.types.PropertyGroup):
    __annotations__ = {
        **with_update(TerrainOptions, _changed),
        "preview": bpy.props.BoolProperty(name="Preview Terrain", update=_changed, default=False,
                                          description="Draw this terrain in the 3D viewport on the GPU, "
                                                      "re-selecting levels as the view moves"),
        "is_terrain": bpy.props.BoolProperty(name="Terrain", default=False, options={"HIDDEN"}),
    }


def copy_terrain_settings(source, target):
    for name in TERRAIN_SETTING_NAMES:
        setattr(target, name, getattr(source, name))


def source_key(s):
    """What the height map and its analysis depend on (a change means: read and analyse again)."""
    return tuple(getattr(s, name) for name in SOURCE_NAMES)


def lod_settings(s, levels=None):
    return TerrainLod(mode=s.mode, g=s.g, ham_scale=s.ham_scale, epsilon=s.epsilon, t_min_rule=s.t_min_rule,
                      d_max=s.d_max, culling=s.culling, levels=levels or s.levels)


def draw_terrain_settings(layout, s, show_source=True):
    layout.use_property_split = True
    layout.use_property_decorate = False
    col = layout.column()
    if show_source:
        col.prop(s, "source")
        if s.source == "FILE":
            col.prop(s, "filepath")
            sub = col.column(align=True)
            sub.prop(s, "raw_width")
            sub.prop(s, "raw_height")
        else:
            col.prop_search(s, "image_name", bpy.data, "images")
        col.prop(s, "texel_size")
        col.prop(s, "height_scale")
        col.prop(s, "height_offset")
        col.prop(s, "tile_size")
    col = layout.column()
    col.prop(s, "mode")
    if s.mode == "OURS":
        col.prop(s, "g")
        col.prop(s, "ham_scale")
        col.prop(s, "t_min_rule")
    col.prop(s, "epsilon")
    col.prop(s, "d_max")
    col.prop(s, "levels")
    col.prop(s, "culling")
    col.prop(s, "camera_source")


classes = (TESSERA_PG_terrain,)
register, unregister = bpy.utils.register_classes_factory(classes)

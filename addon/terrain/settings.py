"""Terrain settings: one set of properties shared by ``tessera.terrain_add`` (redo panel) and
``Object.tessera.terrain`` (bake, preview and batch re-runs). `lod_settings` turns them into
`kernels.terrain.lod.TerrainLod`; `source_key` says when the height map must be read and analysed again."""

import bpy

from ...kernels.common.limits import MAX_FACTOR, MAX_PIXELS, MAX_WORLD_VALUE
from ...kernels.terrain import geotiff
from ...kernels.terrain.lod import TerrainLod
from ..cameras import CAMERA_ITEMS
from ..settings_scaffold import stored_options
from ..viewport import invalidator

SOURCE_ITEMS = (
    ("FILE", "File", "Elevation data (GeoTIFF, SRTM .hgt, ESRI .asc, ERDAS .img, GDAL .vrt...), PNG/TIFF (8 or 16 "
                     "bit), EXR/TIFF (float) or raw .r16/.r32 files"),
    ("IMAGE", "Image", "An image in this Blender file (its first channel)"),
)
MODE_ITEMS = (
    ("OURS", "Adaptive", "Detail where the ground is rough, as much as the screen error needs and no more"),
    ("DISTANCE", "Distance Only", "Detail falls with camera distance alone (flat ground is refined too)"),
    ("UNIFORM", "Uniform", "The most detail everywhere (one quad per texel)"),
)
G_ITEMS = (
    ("SQRT", "Square Root", "The most detail grows with the square root of the roughness"),
    ("LOG", "Logarithm", "The most detail grows slowly, with the logarithm of the roughness"),
)
T_MIN_ITEMS = (
    ("SEARCH", "Search", "The coarsest power-of-two grid that keeps each tile's peak within the error (exact)"),
    ("LOG2", "Closed Form", "A formula from the peak's height and the error (faster, approximate)"),
    ("PRINTED", "Reversed Closed Form", "The formula with its ratio reversed: never adds detail (for comparisons)"),
)
VOID_ITEMS = (
    ("FILL", "Fill", "Fill each no-data void smoothly from the heights around it"),
    ("HOLES", "Holes", "Leave each no-data void out of the mesh"),
)
LEVEL_ITEMS = (
    ("POW2", "Powers of Two", "Vertices land on texels and stay put as levels change (no swimming)"),
    ("INTEGER", "Integer", "Whole levels"),
    ("FRACTIONAL", "Fractional", "Continuous levels: the mesh changes smoothly, no popping while the camera moves"),
)


class TerrainOptions:
    """The terrain options, declared once: ``tessera.terrain_add`` inherits them as they are, and
    `TESSERA_PG_terrain` (``Object.tessera.terrain``) takes them with the preview's invalidation added
    (`addon.settings_scaffold`). The identifiers ``g`` and ``ham_scale`` (the roughness curve and scale) are stored in
    files."""

    source: bpy.props.EnumProperty(name="Source", items=SOURCE_ITEMS, default="FILE",
                                   description="Read the heights from a file or from an image in this Blender file")
    filepath: bpy.props.StringProperty(name="Height Map", subtype="FILE_PATH",
                                       description="The height map file (GeoTIFF, .hgt, .asc, .img, .vrt, PNG, TIFF, "
                                                   "EXR, or raw .r16/.r32)")
    tile_files: bpy.props.StringProperty(name="More Tiles",
                                         description="Other files of the same elevation data (adjacent "
                                                     "tiles) in the height map's folder, separated by semicolons: "
                                                     "they become one terrain")
    georeferenced: bpy.props.BoolProperty(name="Use Georeferencing", default=True,
                                          description="For elevation files: take the texel size, the height units "
                                                      "and the position from the file (Texel Size and Height Scale "
                                                      "are then not used)")
    band: bpy.props.IntProperty(name="Band", default=0, min=0, soft_max=16,
                                description="Which band of the file holds the heights (0: the only one; a picture's "
                                            "colour bands are not heights)")
    exaggeration: bpy.props.FloatProperty(name="Vertical Exaggeration", default=1.0, min=0.0, max=MAX_FACTOR,
                                          soft_max=10.0,
                                          description="Factor on an elevation file's heights (1: true scale)")
    voids: bpy.props.EnumProperty(name="No-Data", items=VOID_ITEMS, default="FILL",
                                  description="What becomes of samples the file marks as having no height "
                                              "(voids, sea)")
    image_name: bpy.props.StringProperty(name="Image", description="Blender image with the heights")
    raw_width: bpy.props.IntProperty(name="Raw Width", default=0, min=0, soft_max=65536, subtype="PIXEL",
                                     description="Samples per row of a raw .r16/.r32 file")
    raw_height: bpy.props.IntProperty(name="Raw Height", default=0, min=0, soft_max=65536, subtype="PIXEL",
                                      description="Rows of a raw .r16/.r32 file")
    texel_size: bpy.props.FloatProperty(name="Texel Size", default=1.0, min=1e-6, max=MAX_WORLD_VALUE,
                                        soft_max=100.0, subtype="DISTANCE", unit="LENGTH",
                                        description="Distance between neighbouring samples")
    height_scale: bpy.props.FloatProperty(name="Height Scale", default=100.0, min=-MAX_WORLD_VALUE,
                                          max=MAX_WORLD_VALUE, soft_min=-10000.0, soft_max=10000.0,
                                          subtype="DISTANCE", unit="LENGTH",
                                          description="Height of a full-scale integer sample (255 or 65535); "
                                          "the factor on float samples")
    height_offset: bpy.props.FloatProperty(name="Height Offset", default=0.0, min=-MAX_WORLD_VALUE,
                                           max=MAX_WORLD_VALUE, soft_min=-10000.0, soft_max=10000.0,
                                           subtype="DISTANCE", unit="LENGTH", description="Added to every height")
    tile_size: bpy.props.IntProperty(name="Tile Size", default=64, min=2, max=1024, subtype="PIXEL",
                                     description="Texels per tile side (64: one quad per texel at the most detail)")
    mode: bpy.props.EnumProperty(name="Level Mode", items=MODE_ITEMS, default="OURS",
                                 description="What decides how much detail each tile gets")
    g: bpy.props.EnumProperty(name="Detail Curve", items=G_ITEMS, default="SQRT",
                              description="How a tile's most detail grows with its roughness (how sharply its slope "
                                          "changes)")
    ham_scale: bpy.props.FloatProperty(name="Detail Scale", default=4.0, min=1e-3, max=MAX_FACTOR, soft_max=64.0,
                                       description="How much detail roughness buys (a factor in the Detail Curve)")
    epsilon: bpy.props.FloatProperty(name="Screen Error", default=3.0, min=0.05, max=MAX_PIXELS, soft_max=32.0,
                                     subtype="PIXEL",
                                     description="Largest error allowed on screen: how far a tile's peak may be drawn "
                                                 "from its true height")
    t_min_rule: bpy.props.EnumProperty(name="Error Rule", items=T_MIN_ITEMS, default="SEARCH",
                                       description="How the least detail that keeps the Screen Error is found")
    d_max: bpy.props.FloatProperty(name="Detail Distance", default=0.0, min=0.0, max=MAX_WORLD_VALUE,
                                   soft_max=10000.0, subtype="DISTANCE", unit="LENGTH",
                                   description="Closer than this, tiles get their most detail (0: where a texel "
                                   "spans 4 pixels)")
    levels: bpy.props.EnumProperty(name="Level Steps", items=LEVEL_ITEMS, default="POW2",
                                   description="Which levels tiles may take")
    culling: bpy.props.BoolProperty(name="Frustum Culling", default=True,
                                    description="Drop tiles outside the camera's view")
    camera_source: bpy.props.EnumProperty(name="Camera", items=CAMERA_ITEMS, default="SCENE",
                                          description="Whose view sets the detail")


#: The invalidation topic of these settings (`addon.viewport`): the preview forgets what a change makes stale.
TOPIC = "terrain"
_changed = invalidator(TOPIC)
SOURCE_NAMES = ("source", "filepath", "tile_files", "georeferenced", "band", "exaggeration", "voids", "image_name",
                "raw_width", "raw_height", "texel_size", "height_scale", "height_offset", "tile_size")


class TESSERA_PG_terrain(bpy.types.PropertyGroup):
    __annotations__ = stored_options(
        TerrainOptions, _changed,
        preview=bpy.props.BoolProperty(name="Preview Terrain", update=_changed, default=False,
                                       description="Draw this terrain in the 3D viewport on the GPU, re-selecting "
                                                   "levels as the view moves"),
        is_terrain=bpy.props.BoolProperty(name="Terrain", default=False, options={"HIDDEN"}))


def is_elevation_file(path):
    """Whether a height-map path names an elevation file (which may carry its placement)."""
    return geotiff.is_elevation_file(path)


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
        geo = s.source == "FILE" and s.georeferenced and is_elevation_file(s.filepath)
        if s.source == "FILE":
            col.prop(s, "filepath")
            if is_elevation_file(s.filepath):
                col.prop(s, "tile_files")
                col.prop(s, "georeferenced")
                if geo:
                    col.prop(s, "band")
                col.prop(s, "voids")
            else:
                sub = col.column(align=True)
                sub.prop(s, "raw_width")
                sub.prop(s, "raw_height")
        else:
            col.prop_search(s, "image_name", bpy.data, "images")
        if geo:
            col.prop(s, "exaggeration")
        sub = col.column()
        sub.active = not geo  # a GeoTIFF gives them (a plain TIFF keeps them: it has no georeferencing)
        sub.prop(s, "texel_size")
        sub.prop(s, "height_scale")
        col.prop(s, "height_offset")
        col.prop(s, "tile_size")
    col = layout.column()
    col.prop(s, "mode")
    if s.mode == "OURS":
        col.prop(s, "g")
        col.prop(s, "ham_scale")  # t_min_rule (the Error Rule) is for scripts: research comparisons, not artists
    col.prop(s, "epsilon")
    col.prop(s, "d_max")
    col.prop(s, "levels")
    col.prop(s, "culling")
    col.prop(s, "camera_source")


classes = (TESSERA_PG_terrain,)
register, unregister = bpy.utils.register_classes_factory(classes)

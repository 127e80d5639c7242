"""Tube settings: one set of properties shared by ``tessera.tubes`` (redo panel) and ``Object.tessera.tubes``
(the viewport preview and batch re-runs). `kernel_settings` turns either into `kernels.tubes.builder.TubeSettings`."""

import math

import bpy

from ...kernels.common.limits import MAX_PIXELS, MAX_WORLD_VALUE
from ...kernels.tubes.builder import TubeSettings
from ..cameras import CAMERA_ITEMS
from ..settings_scaffold import stored_options
from ..viewport import invalidator

RADIUS_ITEMS = (
    ("POINT", "From Points", "Curves: point radius times Radius (like a bevel); hair: its 'radius' attribute "
     "(Radius where it has none); mesh edges: Radius"),
    ("CONSTANT", "Constant", "The same radius everywhere"),
    ("ATTRIBUTE", "Attribute", "A float point attribute times Radius (hair curves and meshes)"),
)
SIDES_ITEMS = (
    ("FIXED", "Fixed", "The same number of sides on every tube"),
    ("CAMERA", "Camera", "Sides per tube from its projected size (level of detail)"),
)
CAP_ITEMS = (
    ("NONE", "None", "Open ends"),
    ("FLAT", "Flat", "One flat face per end (closed, manifold)"),
    ("ROUND", "Round", "A hemisphere on each end (closed, manifold)"),
)
REFINE_ITEMS = (
    ("CENTRIPETAL", "Centripetal", "Follows the points without cusps or loops inside a segment"),
    ("UNIFORM", "Uniform", "The classic Catmull-Rom spline (can overshoot between uneven points)"),
)


class TubeOptions:
    """The tube options, declared once: the operator ``tessera.tubes`` inherits them as they are, and
    `TESSERA_PG_tubes` (``Object.tessera.tubes``) takes them with the preview's invalidation added
    (`addon.settings_scaffold`)."""

    radius_source: bpy.props.EnumProperty(name="Radius From", items=RADIUS_ITEMS, default="POINT",
                                          description="Where each point's tube radius comes from")
    radius: bpy.props.FloatProperty(name="Radius", description="Radius, or the factor on curve point radii",
                                    default=0.05, min=0.0, max=MAX_WORLD_VALUE, soft_max=10.0, subtype="DISTANCE",
                                    unit="LENGTH")
    attribute: bpy.props.StringProperty(name="Attribute", description="Float point attribute with the radius",
                                        default="radius")
    caps: bpy.props.EnumProperty(name="Caps", items=CAP_ITEMS, default="FLAT",
                                 description="How the ends of open tubes are closed")
    sides_mode: bpy.props.EnumProperty(name="Sides From", items=SIDES_ITEMS, default="FIXED",
                                       description="A fixed number of sides, or fewer sides the smaller a tube looks")
    sides: bpy.props.IntProperty(name="Sides", default=8, min=3, max=1024, soft_max=64,
                                 description="Faces around every tube")
    min_sides: bpy.props.IntProperty(name="Min Sides", default=3, min=3, max=1024, soft_max=64,
                                     description="Fewest faces around a tube, however small it looks")
    max_sides: bpy.props.IntProperty(name="Max Sides", default=32, min=3, max=1024, soft_max=64,
                                     description="Most faces around a tube, however close it is")
    edge_pixels: bpy.props.FloatProperty(name="Edge Pixels", description="Target width of one side on screen",
                                         default=8.0, min=0.5, max=MAX_PIXELS, soft_max=64.0, subtype="PIXEL")
    camera_source: bpy.props.EnumProperty(name="Camera", items=CAMERA_ITEMS, default="SCENE",
                                          description="Whose view sets the sides and the pixel clamp")
    aa_clamp: bpy.props.BoolProperty(name="Pixel Clamp", default=False, description="Keep every tube at least "
                                     "one pixel in radius for the camera (thin tubes stay visible far away)")
    max_radius: bpy.props.FloatProperty(name="Max Clamp Radius", description="Cap of the clamp's inflation "
                                        "(0: none)", default=0.0, min=0.0, max=MAX_WORLD_VALUE, soft_max=10.0,
                                        subtype="DISTANCE", unit="LENGTH")
    refine: bpy.props.IntProperty(name="Refine", default=1, min=1, max=64,
                                  description="Smooth sparse points: spline segments per input segment (1: off)")
    refine_kind: bpy.props.EnumProperty(name="Spline", items=REFINE_ITEMS, default="CENTRIPETAL",
                                         description="The spline through the points when Refine is above 1")
    select_angle: bpy.props.FloatProperty(name="Angle Tolerance", subtype="ANGLE", default=0.0, min=0.0,
                                          max=math.pi / 2, description="Keep a point only where the tangent has "
                                          "turned this much (0: keep all points)")
    uvs: bpy.props.BoolProperty(name="UVs", default=True, description="UV map: U along the tube, V around it")
    curve_sampling: bpy.props.EnumProperty(name="Curve Sampling", default="RESOLUTION",
                                           description="Where rings go along curve objects", items=(
        ("RESOLUTION", "Resolution", "Curve objects at Blender's own resolution (every segment the same)"),
        ("CURVATURE", "Curvature", "Bézier segments by how much they bend: 6 where straight, up to "
                                   "Max Segments in a bend")))
    max_segments: bpy.props.IntProperty(name="Max Segments", default=32, min=6, max=1024,
                                        description="Most segments a Bézier segment gets by curvature")


#: The invalidation topic of these settings (`addon.viewport`): the preview forgets what a change makes stale.
TOPIC = "tubes"
_changed = invalidator(TOPIC)


class TESSERA_PG_tubes(bpy.types.PropertyGroup):
    __annotations__ = stored_options(TubeOptions, _changed, preview=bpy.props.BoolProperty(
        name="Preview Tubes", update=_changed, default=False,
        description="Draw this object's tubes in the 3D viewport on the GPU (no mesh is made)"))


def kernel_settings(s, aa_clamp=None):
    return TubeSettings(
        sides=s.sides, sides_mode=s.sides_mode, min_sides=s.min_sides, max_sides=max(s.min_sides, s.max_sides),
        edge_pixels=s.edge_pixels, refine=s.refine, refine_kind=s.refine_kind, select_angle=s.select_angle,
        aa_clamp=s.aa_clamp if aa_clamp is None else aa_clamp, max_radius=s.max_radius, caps=s.caps, uvs=s.uvs,
        point_normals=False)  # Blender derives a written mesh's normals


def draw_tubes_settings(layout, s):
    layout.use_property_split = True
    layout.use_property_decorate = False
    col = layout.column()
    col.prop(s, "radius_source")
    col.prop(s, "radius")
    if s.radius_source == "ATTRIBUTE":
        col.prop(s, "attribute")
    col.prop(s, "caps")
    col.prop(s, "sides_mode")
    if s.sides_mode == "FIXED":
        col.prop(s, "sides")
    else:
        col.prop(s, "min_sides")
        col.prop(s, "max_sides")
        col.prop(s, "edge_pixels")
    col.prop(s, "aa_clamp")
    if s.aa_clamp:
        col.prop(s, "max_radius")
    if s.sides_mode == "CAMERA" or s.aa_clamp:
        col.prop(s, "camera_source")
    col.prop(s, "curve_sampling")
    if s.curve_sampling == "CURVATURE":
        col.prop(s, "max_segments")
    col.prop(s, "refine")
    if s.refine > 1:
        col.prop(s, "refine_kind")
    col.prop(s, "select_angle")
    col.prop(s, "uvs")


classes = (TESSERA_PG_tubes,)
register, unregister = bpy.utils.register_classes_factory(classes)

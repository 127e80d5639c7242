"""Surface and curve options.

Parametric surfaces: declared once from the kernel's surface dataclasses, one float property per shape parameter of
each surface (``torus_major``, ``cone_height``, ...) with the dataclass's default, so a new surface in
`kernels.surfaces.parametric.SURFACES` gets its options without code here. `surface_from` makes the kernel's surface
from them; `draw_surface_options` shows the chosen surface's parameters only.

Adaptive curves: `CurveOptions`, made into the kernel's `CurveSampling` by `curve_sampling`."""

import dataclasses

import bpy

from ...kernels.common.curves.bezier_curves import CurveSampling
from ...kernels.common.errors import InvalidInputError
from ...kernels.common.limits import MAX_PIXELS, MAX_WORLD_VALUE
from ...kernels.surfaces.bezier_patches import PatchLod
from ...kernels.surfaces.domain_mesh import MAX_FACTOR
from ...kernels.surfaces.parametric import SURFACES
from ..cameras import CAMERA_ITEMS
from ..settings_scaffold import stored_options
from ..viewport import invalidator

#: (identifier, label, description) of each surface, in menu order.
SURFACE_ITEMS = (
    ("SPHERE", "Sphere", "A sphere, closed at its poles"),
    ("CONE", "Cone", "A cone, open at its base"),
    ("TORUS", "Torus", "A ring-shaped tube"),
    ("STEINER", "Steiner's Roman Surface", "A closed surface that passes through itself (a projective plane)"),
    ("KLEIN", "Klein Bottle", "The figure-8 Klein bottle"),
    ("MOBIUS", "Möbius Band", "A band with a half twist"),
    ("TREFOIL", "Trefoil Knot Tube", "A tube around the trefoil knot"),
    ("SUPERELLIPSOID", "Superellipsoid", "Between an octahedron (2), a sphere (1) and a cube (→ 0)"),
)


def parameter_name(kind, field):
    return f"{kind.lower()}_{field}"


def _parameters():
    """(property name, surface kind, dataclass field) of every shape parameter."""
    return [(parameter_name(kind, f.name), kind, f) for kind, cls in SURFACES.items()
            for f in dataclasses.fields(cls)]


def _annotations():
    out = {
        "surface": bpy.props.EnumProperty(name="Surface", items=SURFACE_ITEMS, default="TORUS",
                                          description="Which surface to make"),
        "factor": bpy.props.IntProperty(name="Factor", default=32, min=1, soft_min=2, max=MAX_FACTOR,
                                        description="Quads along each side of the surface's grid (2 × Factor² "
                                                    "triangles)"),
    }
    for name, _, f in _parameters():
        length = f.metadata.get("unit") == "LENGTH"
        out[name] = bpy.props.FloatProperty(name=f.metadata["label"], description=f.metadata["description"],
                                            default=f.default, min=1e-6, max=MAX_WORLD_VALUE, soft_max=10.0,
                                            subtype="DISTANCE" if length else "NONE",
                                            unit="LENGTH" if length else "NONE")
    return out


class ParametricOptions:
    """The parametric-surface options (``tessera.parametric_surface_add`` inherits them)."""

    __annotations__ = _annotations()


#: The invalidation topic of the live surfaces' settings (`addon.viewport`).
TOPIC = "surfaces"
_changed = invalidator(TOPIC)


class TESSERA_PG_surfaces(bpy.types.PropertyGroup):
    """``Object.tessera.surface``: an object with no mesh of its own drawn as a one-point surface (the GPU path:
    one instance per control point) and baked on demand."""

    __annotations__ = stored_options(
        ParametricOptions, _changed,
        is_surface=bpy.props.BoolProperty(name="Parametric Surface", default=False, update=_changed,
                                          description="Draw this object as its parametric surface"),
        instance_object=bpy.props.PointerProperty(
            name="Control Points", type=bpy.types.Object, update=_changed,
            description="A mesh whose vertices are control points: one surface at each (none: one surface at this "
                        "object's origin)"),
        factor_mode=bpy.props.EnumProperty(name="Factor From", default="FIXED", update=_changed, items=(
            ("FIXED", "Fixed", "Every copy at Factor"),
            ("CAMERA", "Camera", "Each copy's factor from its size on screen (Edge Pixels a segment)")),
            description="A fixed factor, or a factor per copy from how large it looks"),
        edge_pixels=bpy.props.FloatProperty(name="Edge Pixels", default=8.0, min=0.5, max=MAX_PIXELS,
                                            soft_max=100.0, subtype="PIXEL", update=_changed,
                                            description="Target segment length on screen"))


def surface_from(options):
    """The kernel surface the options describe (a `kernels.surfaces.parametric` dataclass)."""
    cls = SURFACES[options.surface]
    return cls(**{f.name: getattr(options, parameter_name(options.surface, f.name))
                  for f in dataclasses.fields(cls)})


def draw_surface_options(layout, options):
    layout.use_property_split = True
    layout.use_property_decorate = False
    col = layout.column()
    col.prop(options, "surface")
    col.prop(options, "factor")
    for name, kind, _ in _parameters():
        if kind == options.surface:
            col.prop(options, name)


CURVE_MODE_ITEMS = (
    ("CURVATURE", "Curvature", "Segments by how much each Bézier segment bends: 6 where straight, up to Max "
                               "Segments"),
    ("TOLERANCE", "Tolerance", "As many segments as keep the polyline within Tolerance of the curve"),
    ("SCREEN", "Screen", "As many segments as keep the polyline within Pixels of the curve for the camera"),
)


class CurveOptions:
    """The options of ``tessera.curve_adaptive`` (`kernels.common.curves.bezier_curves.CurveSampling`)."""

    mode: bpy.props.EnumProperty(name="Sampling", items=CURVE_MODE_ITEMS, default="CURVATURE",
                                 description="What decides how many segments each Bézier segment gets")
    max_segments: bpy.props.IntProperty(name="Max Segments", default=32, min=6, max=1024, soft_max=128,
                                        description="Most segments one Bézier segment gets")
    tolerance: bpy.props.FloatProperty(name="Tolerance", default=0.01, min=1e-9, max=MAX_WORLD_VALUE, soft_max=1.0,
                                       subtype="DISTANCE", unit="LENGTH",
                                       description="Largest distance between the polyline and the curve")
    pixels: bpy.props.FloatProperty(name="Screen Error", default=1.0, min=0.01, max=MAX_PIXELS, soft_max=16.0,
                                    subtype="PIXEL",
                                    description="Largest distance between the polyline and the curve on screen")
    camera_source: bpy.props.EnumProperty(name="Camera", items=CAMERA_ITEMS, default="SCENE",
                                          description="Whose view the Pixels are measured in")
    copies: bpy.props.IntProperty(name="Copies", default=1, min=1, max=1000, soft_max=100,
                                  description="Polylines per spline (hair-like strands), copy k moved by Copy Offset × "
                                              "k / Copies")
    copy_offset: bpy.props.FloatVectorProperty(name="Copy Offset", default=(0.0, 0.0, 0.1), size=3,
                                               min=-MAX_WORLD_VALUE, max=MAX_WORLD_VALUE, soft_min=-10.0,
                                               soft_max=10.0, subtype="TRANSLATION", unit="LENGTH",
                                               description="How far the last copy is moved from the first")


def curve_sampling(options):
    """The kernel's `CurveSampling` from `CurveOptions`."""
    return CurveSampling(mode=options.mode, max_segments=options.max_segments, tolerance=options.tolerance,
                         pixels=options.pixels, copies=options.copies, offset=tuple(options.copy_offset))


def draw_curve_options(layout, options):
    layout.use_property_split = True
    layout.use_property_decorate = False
    col = layout.column()
    col.prop(options, "mode")
    col.prop(options, "max_segments")
    if options.mode == "TOLERANCE":
        col.prop(options, "tolerance")
    elif options.mode == "SCREEN":
        col.prop(options, "pixels")
        col.prop(options, "camera_source")
    col.prop(options, "copies")
    if options.copies > 1:
        col.prop(options, "copy_offset")


PATCH_METRIC_ITEMS = (
    ("CURVATURE", "Curvature", "From how much each patch bends along its rows, columns and diagonals"),
    ("DISTANCE", "Distance", "From the camera distance: sides from their nearest control point, the inside from the "
                             "patch's centre"),
    ("EDGE_LENGTH", "Edge Length", "From each side's length on screen, Edge Pixels a segment"),
    ("TOLERANCE", "Tolerance", "As many as keep the mesh within Tolerance of the surface, measured"),
)


class PatchOptions:
    """The options of ``tessera.surface_tessellate`` (`kernels.surfaces.bezier_patches.PatchLod`)."""

    metrics: bpy.props.EnumProperty(name="Metrics", items=PATCH_METRIC_ITEMS, default={"TOLERANCE"},
                                    options={"ENUM_FLAG"}, description="Levels from these, the largest wins")
    tolerance: bpy.props.FloatProperty(name="Tolerance", default=0.001, min=1e-7, max=MAX_WORLD_VALUE, soft_min=1e-5,
                                       soft_max=1.0, precision=5, subtype="DISTANCE", unit="LENGTH",
                                       description="Largest distance allowed between the mesh and the surface")
    max_level: bpy.props.IntProperty(name="Max Level", default=32, min=1, max=64,
                                     description="Most segments on a side or inside a patch")
    inner_rows: bpy.props.EnumProperty(name="Inner Curvature", default="ALL", items=(
        ("ALL", "All Rows", "Every row and column of the control net"),
        ("INTERIOR", "Interior Rows", "Only the control net's two inner rows and columns")),
        description="Which rows of a patch's control net set the level inside it")
    degenerate: bpy.props.EnumProperty(name="Collapsed Rows", default="CAP", items=(
        ("CAP", "Cap", "A row of the net that is one point (a pole) counts as the most curved: poles get the most "
                       "detail"),
        ("ZERO", "Flat", "Such a row counts as straight")),
        description="How a row of the control net that collapses to one point (a pole) counts")
    near: bpy.props.FloatProperty(name="Near", default=1.0, min=0.0, max=MAX_WORLD_VALUE, soft_max=1000.0,
                                  subtype="DISTANCE", unit="LENGTH",
                                  description="Camera distance that gets Max Level")
    far: bpy.props.FloatProperty(name="Far", default=20.0, min=1e-4, max=MAX_WORLD_VALUE, soft_max=1000.0,
                                 subtype="DISTANCE", unit="LENGTH",
                                 description="Camera distance beyond which the level is 1")
    mapping: bpy.props.EnumProperty(name="Distance Map", default="LINEAR", items=(
        ("LINEAR", "Linear", "Max Level at Near, falling linearly to 1 at Far"),
        ("INVERSE", "Inverse", "Like a z-buffer: more levels near the camera")),
        description="How the level falls from Near to Far")
    edge_pixels: bpy.props.FloatProperty(name="Edge Pixels", default=10.0, min=0.5, max=MAX_PIXELS, soft_max=100.0,
                                         subtype="PIXEL",
                                         description="Segment length on screen for the Edge Length metric")
    camera_source: bpy.props.EnumProperty(name="Camera", items=CAMERA_ITEMS, default="SCENE",
                                          description="Whose view sets the levels")

def patch_lod(options):
    if not options.metrics:
        raise InvalidInputError("Choose at least one metric for the levels")
    return PatchLod(metrics=tuple(sorted(options.metrics)), max_level=options.max_level,
                    inner_rows=options.inner_rows, near=options.near, far=options.far, mapping=options.mapping,
                    edge_pixels=options.edge_pixels, degenerate=options.degenerate, tolerance=options.tolerance)


def draw_patch_options(layout, options):
    layout.use_property_split = True
    layout.use_property_decorate = False
    col = layout.column()
    col.prop(options, "metrics")
    col.prop(options, "max_level")
    if "TOLERANCE" in options.metrics:
        col.prop(options, "tolerance")
    if "CURVATURE" in options.metrics:
        col.prop(options, "inner_rows")
        col.prop(options, "degenerate")
    if "DISTANCE" in options.metrics:
        for name in ("near", "far", "mapping"):
            col.prop(options, name)
    if "EDGE_LENGTH" in options.metrics:
        col.prop(options, "edge_pixels")
    if options.metrics & {"DISTANCE", "EDGE_LENGTH"}:
        col.prop(options, "camera_source")


classes = (TESSERA_PG_surfaces,)
register, unregister = bpy.utils.register_classes_factory(classes)

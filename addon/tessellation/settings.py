"""Tessellation settings: one set of properties shared by the operator (redo panel) and the object.

The same annotations define `TESSERA_PG_tessellation` (stored on every object as ``Object.tessera.tessellate``,
so a batch script can re-run what the artist chose) and the properties of ``tessera.tessellate``.
`addon.settings_scaffold.copy_options` moves values between the two; `surface_options` and `adaptive_settings` turn
either into the kernels' dataclasses.
"""

import bpy

from ...kernels.common.limits import MAX_FACTOR, MAX_PIXELS, MAX_WORLD_VALUE
from ...kernels.common.partition import MAX_LEVEL
from ...kernels.tessellation.adaptive import AdaptiveSettings
from ...kernels.tessellation.tessellate import SurfaceOptions
from ..cameras import CAMERA_ITEMS
from ..viewport import invalidator

METHOD_ITEMS = (
    ("PN", "PN Triangles", "A smooth cubic surface through the corners, shaped by the vertex normals (smoothest)"),
    ("PHONG", "Phong", "A rounded surface that bulges toward the vertex normals, as far as the Shape Factor says"),
    ("LINEAR", "Linear", "New vertices on the flat triangles: same shape, more vertices"),
)
LEVEL_MODE_ITEMS = (
    ("UNIFORM", "Uniform", "The same level on every edge"),
    ("ADAPTIVE", "Adaptive", "Each edge gets its own level from the chosen metrics; no cracks between levels"),
)
SPACING_ITEMS = (
    ("EQUAL", "Equal", "The level rounded up to a whole number of equal segments"),
    ("FRACTIONAL_EVEN", "Fractional Even", "Even segment counts; vertices slide continuously as the level changes"),
)
NORMAL_MODE_ITEMS = (
    ("WATERTIGHT", "Watertight", "Sharp edges stay closed: geometry uses one averaged normal per vertex, "
     "shading keeps the split normals"),
    ("SPLIT", "Split", "Geometry follows the split normals: the surface opens along sharp edges"),
)
PN_NORMAL_ITEMS = (
    ("QUADRATIC", "Quadratic", "Quadratic normal patch: shows inflections (folds)"),
    ("LINEAR", "Linear", "Linearly interpolated normals"),
)
METRIC_ITEMS = (
    ("PROJECTED", "Edge Length", "Split edges longer than a number of pixels on screen"),
    ("DISTANCE", "Distance", "More levels near the camera"),
    ("SILHOUETTE", "Silhouette", "Refine edges on the silhouette seen from the camera"),
    ("CURVATURE", "Curvature", "Refine where the surface bends (no camera needed)"),
)
POWER_ITEMS = (
    ("NONE", "None", "Keep levels as computed"),
    ("CEIL", "Up", "Round up to a power of two (fewer distinct patterns, more triangles)"),
    ("FLOOR", "Down", "Round down to a power of two"),
    ("NEAREST", "Nearest", "Round to the nearest power of two (in log scale)"),
)
DISTANCE_MAP_ITEMS = (
    ("LINEAR", "Linear", "Level falls linearly from near to far"),
    ("INVERSE", "Inverse", "Level falls like a z-buffer: most detail close to the camera"),
)
EVALUATE_ITEMS = (
    ("CPU", "CPU", "Evaluate the surface on the CPU"),
    ("GPU", "GPU", "Evaluate the surface with a compute shader (same surface; falls back to the CPU without a GPU)"),
)
OUTPUT_ITEMS = (
    ("NEW_OBJECT", "New Object", "Create a new object beside the source (from the evaluated mesh, with modifiers)"),
    ("REPLACE", "Replace Mesh", "Replace the object's own mesh data (modifiers stay and apply on top)"),
)


class TessellateOptions:
    """The tessellation options, declared once: the operator ``tessera.tessellate`` and `TESSERA_PG_tessellation`
    (``Object.tessera.tessellate``) both inherit them."""

    method: bpy.props.EnumProperty(name="Method", items=METHOD_ITEMS, default="PN",
                                   description="How the new vertices are placed: on a curved surface or the flat "
                                               "triangles")
    level_mode: bpy.props.EnumProperty(name="Level Mode", items=LEVEL_MODE_ITEMS, default="UNIFORM",
                                       description="One level everywhere, or a level per edge from what the camera "
                                                   "sees and how the surface bends")
    level: bpy.props.FloatProperty(
        name="Level", description="Segments per edge (and inner level) for every triangle",
        default=3.0, min=1.0, max=float(MAX_LEVEL), soft_max=16.0, step=100, precision=2)
    spacing: bpy.props.EnumProperty(name="Segments", items=SPACING_ITEMS, default="EQUAL",
                                    description="How a fractional level splits an edge")
    alpha: bpy.props.FloatProperty(
        name="Shape Factor", description="How far the surface bulges toward the normals: 0 flat, 1 fully rounded",
        default=0.75, soft_min=0.0, soft_max=1.0, min=-1.0, max=2.0, subtype="FACTOR")
    alpha_attribute: bpy.props.StringProperty(
        name="Shape Attribute", description="Float point attribute with a per-vertex shape factor (optional)")
    normal_mode: bpy.props.EnumProperty(name="Sharp Edges", items=NORMAL_MODE_ITEMS, default="WATERTIGHT",
                                        description="What the curved surface does at sharp edges and flat faces")
    pn_normals: bpy.props.EnumProperty(name="PN Normals", items=PN_NORMAL_ITEMS, default="QUADRATIC",
                                       description="How shading normals vary across each PN triangle")
    metrics: bpy.props.EnumProperty(name="Metrics", items=METRIC_ITEMS, options={"ENUM_FLAG"},
                                    default={"PROJECTED"},
                                    description="What sets each edge's level; with several, the highest level wins")
    max_level: bpy.props.FloatProperty(name="Max Level", description="The highest level an edge can get",
                                       default=16.0, min=1.0, max=float(MAX_LEVEL))
    power_of_two: bpy.props.EnumProperty(name="Power of Two", items=POWER_ITEMS, default="NONE",
                                         description="Round the levels to powers of two")
    edge_pixels: bpy.props.FloatProperty(name="Edge Pixels", description="Target edge length on screen",
                                         default=10.0, min=0.5, max=MAX_PIXELS, soft_max=100.0, subtype="PIXEL")
    distance_map: bpy.props.EnumProperty(name="Distance Map", items=DISTANCE_MAP_ITEMS, default="LINEAR",
                                         description="How the level falls from Near to Far")
    near: bpy.props.FloatProperty(name="Near", description="Camera distance that gets the maximum level",
                                  default=1.0, min=1e-4, max=MAX_WORLD_VALUE, soft_max=1000.0, subtype="DISTANCE",
                                  unit="LENGTH")
    far: bpy.props.FloatProperty(name="Far", description="Camera distance beyond which the level is 1",
                                 default=20.0, min=1e-3, max=MAX_WORLD_VALUE, soft_max=1000.0, subtype="DISTANCE",
                                 unit="LENGTH")
    silhouette_beta: bpy.props.FloatProperty(
        name="Silhouette Ramp", description="How far into a triangle on the silhouette the extra detail reaches",
        default=0.25, min=1e-4, max=1.0, subtype="FACTOR")
    curvature_gain: bpy.props.FloatProperty(name="Curvature Gain", description="Levels per unit of curvature",
                                            default=10.0, min=0.0, max=MAX_FACTOR, soft_max=50.0)
    camera_source: bpy.props.EnumProperty(name="Camera", items=CAMERA_ITEMS, default="SCENE",
                                          description="Whose view sets the levels")
    evaluate_on: bpy.props.EnumProperty(name="Evaluate On", items=EVALUATE_ITEMS, default="CPU",
                                        description="Where the surface is computed (the same surface either way)")
    output: bpy.props.EnumProperty(name="Output", items=OUTPUT_ITEMS, default="NEW_OBJECT",
                                   description="Make a new object, or replace this object's mesh")



#: The invalidation topic of these settings (`addon.viewport`).
TOPIC = "tessellation"
_redraw = invalidator(TOPIC)


class TESSERA_PG_tessellation(TessellateOptions, bpy.types.PropertyGroup):
    stored: bpy.props.BoolProperty(name="Stored", description="These settings were saved by a tessellation run",
                                   default=False)
    preview: bpy.props.BoolProperty(
        name="Live Preview", default=False, update=_redraw,
        description="Draw this mesh tessellated on the GPU with these settings, in place of the mesh, with its "
                    "modifiers (adaptive levels follow the view); no mesh is made")


def surface_options(settings):
    return SurfaceOptions(alpha=settings.alpha, alpha_attribute=settings.alpha_attribute or None,
                          normal_mode=settings.normal_mode, pn_normals=settings.pn_normals)


def adaptive_settings(settings):
    order = [m for m, _, _ in METRIC_ITEMS if m in settings.metrics]
    return AdaptiveSettings(
        metrics=tuple(order), max_level=settings.max_level, power_of_two=settings.power_of_two,
        distance_map=settings.distance_map, near=settings.near, far=settings.far,
        edge_pixels=settings.edge_pixels, silhouette_beta=settings.silhouette_beta,
        curvature_gain=settings.curvature_gain,
    )


def needs_camera(settings):
    return settings.level_mode == "ADAPTIVE" and bool(set(settings.metrics) - {"CURVATURE"})


def draw_settings(layout, settings, show_output=True):
    """The settings UI, shared by the sidebar panel and the redo panel."""
    layout.use_property_split = True
    layout.use_property_decorate = False
    layout.prop(settings, "method")
    if settings.method == "PHONG":
        layout.prop(settings, "alpha")
        ob = bpy.context.active_object
        if ob is not None and ob.type == "MESH":
            layout.prop_search(settings, "alpha_attribute", ob.data, "attributes", text="Shape Attribute")
        else:
            layout.prop(settings, "alpha_attribute")
    if settings.method == "PN":
        layout.prop(settings, "pn_normals")
    if settings.method != "LINEAR":
        layout.prop(settings, "normal_mode")
        layout.prop(settings, "evaluate_on")
    layout.prop(settings, "spacing")
    layout.prop(settings, "level_mode")
    if settings.level_mode == "UNIFORM":
        layout.prop(settings, "level")
    else:
        col = layout.column(heading="Metrics")
        col.prop(settings, "metrics")
        layout.prop(settings, "max_level")
        layout.prop(settings, "power_of_two")
        if "PROJECTED" in settings.metrics:
            layout.prop(settings, "edge_pixels")
        if "DISTANCE" in settings.metrics:
            layout.prop(settings, "distance_map")
            layout.prop(settings, "near")
            layout.prop(settings, "far")
        if "SILHOUETTE" in settings.metrics:
            layout.prop(settings, "silhouette_beta")
        if "CURVATURE" in settings.metrics:
            layout.prop(settings, "curvature_gain")
        if needs_camera(settings):
            layout.prop(settings, "camera_source")
    if show_output:
        layout.prop(settings, "output")


classes = (TESSERA_PG_tessellation,)
register, unregister = bpy.utils.register_classes_factory(classes)

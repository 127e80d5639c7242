"""``tessera.tubes``: tube meshes around curves, hair curves and mesh edges (one new object per source)."""

import math

import bpy
import numpy as np

from ..addon import bridge
from ..addon.cameras import camera_for
from ..addon.preferences import get_preferences
from ..kernels.camera import Camera
from ..kernels.edge_chains import chains_from_edges
from ..kernels.errors import BudgetError, InvalidInputError, TesseraError
from ..kernels.tubes import TubeSettings, build_tubes

SOURCE_TYPES = {"CURVE", "CURVES", "MESH"}
RADIUS_ITEMS = (
    ("POINT", "From Points", "Curves: point radius times Radius (like a bevel); hair: its 'radius' attribute "
     "(Radius where it has none); mesh edges: Radius"),
    ("CONSTANT", "Constant", "The same radius everywhere"),
    ("ATTRIBUTE", "Attribute", "A float point attribute times Radius"),
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
    ("CENTRIPETAL", "Centripetal", "Catmull-Rom with centripetal knots: no cusps or loops inside a segment"),
    ("UNIFORM", "Uniform", "Catmull-Rom with uniform knots (the classic spline)"),
)
CAMERA_ITEMS = (
    ("SCENE", "Scene Camera", "Level of detail and clamp for the scene camera (render and export)"),
    ("VIEWPORT", "Viewport", "Level of detail and clamp for the active 3D viewport"),
)
# output bytes per vertex (position, normal) and per corner (vertex, edge, UV) plus per edge, for the memory guard
_BYTES_PER_VERTEX, _BYTES_PER_CORNER, _BYTES_PER_EDGE = 24, 16, 8


def _object_camera(camera, matrix_world):
    """The camera seen from the object's space (the tubes are built there)."""
    m = np.array(matrix_world, np.float64)
    return Camera(camera.view @ m, camera.projection, camera.width, camera.height)


class TESSERA_OT_tubes(bpy.types.Operator):
    """Build tube meshes around the selected curves, hair curves or mesh edges"""

    bl_idname = "tessera.tubes"
    bl_label = "Tubes"
    bl_options = {"REGISTER", "UNDO"}

    radius_source: bpy.props.EnumProperty(name="Radius From", items=RADIUS_ITEMS, default="POINT")
    radius: bpy.props.FloatProperty(name="Radius", description="Radius, or the factor on point radii",
                                    default=0.05, min=0.0, soft_max=10.0, subtype="DISTANCE")
    attribute: bpy.props.StringProperty(name="Attribute", description="Float point attribute with the radius",
                                        default="radius")
    sides_mode: bpy.props.EnumProperty(name="Sides", items=SIDES_ITEMS, default="FIXED")
    sides: bpy.props.IntProperty(name="Sides", default=8, min=3, max=1024, soft_max=64)
    min_sides: bpy.props.IntProperty(name="Min Sides", default=3, min=3, max=1024)
    max_sides: bpy.props.IntProperty(name="Max Sides", default=32, min=3, max=1024)
    edge_pixels: bpy.props.FloatProperty(name="Side Length (px)", description="Target length of a side on screen",
                                         default=8.0, min=0.5, soft_max=64.0)
    camera_source: bpy.props.EnumProperty(name="Camera", items=CAMERA_ITEMS, default="SCENE")
    aa_clamp: bpy.props.BoolProperty(name="Pixel Clamp", default=False,
                                     description="Keep every tube at least one pixel in radius for the camera "
                                                 "(thin tubes stay visible far away)")
    max_radius: bpy.props.FloatProperty(name="Max Clamp Radius", description="Cap of the clamp's inflation (0: none)",
                                        default=0.0, min=0.0, subtype="DISTANCE")
    caps: bpy.props.EnumProperty(name="Caps", items=CAP_ITEMS, default="FLAT")
    refine: bpy.props.IntProperty(name="Refine", description="Catmull-Rom segments per input segment (1: off)",
                                  default=1, min=1, max=64)
    refine_kind: bpy.props.EnumProperty(name="Spline", items=REFINE_ITEMS, default="CENTRIPETAL")
    select_angle: bpy.props.FloatProperty(name="Angle Tolerance", subtype="ANGLE", default=0.0, min=0.0,
                                          max=math.pi / 2, description="Keep a point only where the tangent has "
                                          "turned this much (0: keep all points)")
    uvs: bpy.props.BoolProperty(name="UVs", default=True, description="UV map: U along the tube, V around it")

    @classmethod
    def poll(cls, context):
        if context.mode != "OBJECT":
            cls.poll_message_set("Switch to Object Mode to build tubes")
            return False
        if not any(ob.type in SOURCE_TYPES for ob in context.selected_objects):
            cls.poll_message_set("Select curves, hair curves or meshes with edges")
            return False
        return True

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        col = layout.column()
        col.prop(self, "radius_source")
        col.prop(self, "radius")
        if self.radius_source == "ATTRIBUTE":
            col.prop(self, "attribute")
        col.prop(self, "caps")
        col.prop(self, "sides_mode")
        if self.sides_mode == "FIXED":
            col.prop(self, "sides")
        else:
            col.prop(self, "min_sides")
            col.prop(self, "max_sides")
            col.prop(self, "edge_pixels")
        col.prop(self, "aa_clamp")
        if self.aa_clamp:
            col.prop(self, "max_radius")
        if self.sides_mode == "CAMERA" or self.aa_clamp:
            col.prop(self, "camera_source")
        col.prop(self, "refine")
        if self.refine > 1:
            col.prop(self, "refine_kind")
        col.prop(self, "select_angle")
        col.prop(self, "uvs")

    def settings(self):
        return TubeSettings(
            sides=self.sides, sides_mode=self.sides_mode, min_sides=self.min_sides,
            max_sides=max(self.min_sides, self.max_sides), edge_pixels=self.edge_pixels, refine=self.refine,
            refine_kind=self.refine_kind, select_angle=self.select_angle, aa_clamp=self.aa_clamp,
            max_radius=self.max_radius, caps=self.caps, uvs=self.uvs)

    def execute(self, context):
        sources = [ob for ob in context.selected_objects if ob.type in SOURCE_TYPES]
        settings = self.settings()
        wm = context.window_manager
        wm.progress_begin(0, 100)
        made = []
        try:
            camera = None
            if settings.sides_mode == "CAMERA" or settings.aa_clamp:
                camera = camera_for(context, self.camera_source)
            results = []
            for i, ob in enumerate(sources):
                def progress(f, i=i):
                    wm.progress_update(int(100 * (i + f) / len(sources)))

                lines, notes = self.read_lines(context, ob)
                cam = _object_camera(camera, ob.matrix_world) if camera is not None else None
                self._check_budget(context, lines, settings)
                poly = build_tubes(lines, settings, cam, progress)
                results.append((ob, poly, notes + poly.notes))
            for ob, poly, notes in results:
                made.append(self._place(context, ob, poly))
                for note in notes:
                    self.report({"WARNING"}, note)
        except TesseraError as err:
            for ob in made:  # leave the scene as it was
                mesh = ob.data
                bpy.data.objects.remove(ob)
                bpy.data.meshes.remove(mesh)
            self.report({"ERROR"}, str(err))
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        for other in context.selected_objects:
            other.select_set(False)
        for ob in made:
            ob.select_set(True)
        if made:
            context.view_layer.objects.active = made[-1]
        return {"FINISHED"}

    def read_lines(self, context, ob):
        """`Polylines` in object space and notes for one source object."""
        notes, vertex_ids = [], None
        if ob.type == "CURVE":
            lines, notes = bridge.read_curve_object(ob, self.radius)  # point radius x Radius, like a bevel
        elif ob.type == "CURVES":
            lines = bridge.read_hair_curves(ob.data, self.radius)  # the 'radius' attribute where present
        else:
            positions, edges = bridge.read_wire_mesh(ob.data)
            lines, vertex_ids = chains_from_edges(positions, edges)
            lines.radius[:] = self.radius
        if self.radius_source == "CONSTANT":
            lines.radius[:] = self.radius
        elif self.radius_source == "ATTRIBUTE":
            if ob.type == "CURVE":
                raise InvalidInputError(f"{ob.name!r} is a curve object: its radius comes From Points")
            count = len(ob.data.vertices) if ob.type == "MESH" else len(lines.points)
            values = bridge.point_float_attribute(ob.data, self.attribute, count)
            lines.radius[:] = (values if vertex_ids is None else values[vertex_ids]) * self.radius
        return lines, notes

    def _check_budget(self, context, lines, settings):
        budget = get_preferences(context).memory_budget_bytes
        sides = settings.sides if settings.sides_mode == "FIXED" else settings.max_sides
        verts = len(lines.points) * sides * max(1, settings.refine)
        need = verts * (_BYTES_PER_VERTEX + 4 * _BYTES_PER_CORNER + 2 * _BYTES_PER_EDGE)
        if budget and need > budget:
            raise BudgetError(f"The tubes would have about {verts:,} vertices and need about {need / 2**20:,.0f} MiB, "
                              f"over the memory budget of {budget / 2**20:,.0f} MiB. Use fewer sides, or raise "
                              "the budget in the Tessera preferences.")

    def _place(self, context, ob, poly):
        mesh = bridge.write_polygons(f"{ob.data.name}.tubes", poly)
        for material in getattr(ob.data, "materials", ()):
            mesh.materials.append(material)
        new = bpy.data.objects.new(f"{ob.name}.tubes", mesh)
        for collection in ob.users_collection:
            collection.objects.link(new)
        new.matrix_world = ob.matrix_world.copy()
        return new


classes = (TESSERA_OT_tubes,)
register, unregister = bpy.utils.register_classes_factory(classes)

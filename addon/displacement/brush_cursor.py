"""Where the displacement brush touches the surface, and its ring: shared by the stroke operator (while
painting) and the tool's hover cursor (a gizmo that follows the mouse without painting)."""

import math

import bpy
import mathutils
import numpy as np

from ...kernels.common.errors import TesseraError
from ...kernels.common.tolerances import FLOAT32_TINY


def texel(mesh, poly_index, co, uv_name, size):
    """Map texel coordinates of the object-space point ``co`` on polygon ``poly_index`` of ``mesh``."""
    poly = mesh.polygons[poly_index]
    weights = mathutils.interpolate.poly_3d_calc([mesh.vertices[i].co for i in poly.vertices], co)
    layer = mesh.uv_layers.get(uv_name) if uv_name else mesh.uv_layers.active
    if layer is None:
        raise TesseraError(f"The mesh has no UV map {uv_name!r}")
    u = sum(w * layer.uv[li].vector.x for w, li in zip(weights, poly.loop_indices, strict=True))
    v = sum(w * layer.uv[li].vector.y for w, li in zip(weights, poly.loop_indices, strict=True))
    return u * size[0] - 0.5, v * size[1] - 0.5


def texel_world_size(ob, mesh, poly_index, uv_name, size):
    """World length of one texel on a polygon (from its area in the world and in texel space)."""
    poly = mesh.polygons[poly_index]
    layer = mesh.uv_layers.get(uv_name) if uv_name else mesh.uv_layers.active
    uv = [layer.uv[li].vector for li in poly.loop_indices]
    uv_area = 0.5 * abs(sum(uv[i].x * uv[i - 1].y - uv[i - 1].x * uv[i].y for i in range(len(uv))))
    scale = ob.matrix_world.to_scale()
    world_area = poly.area * abs(scale.x * scale.y)  # close enough for a cursor
    return math.sqrt(world_area / max(uv_area * size[0] * size[1], FLOAT32_TINY))


class Hit:
    """A ray's hit on the (displaced) surface of ``ob``: object-space ``co``, ``normal``, ``index`` (polygon) on
    the evaluated object ``evaluated``."""

    def __init__(self, ob, evaluated, co, normal, index):
        self.ob, self.evaluated, self.co, self.normal, self.index = ob, evaluated, co, normal, index

    def ring(self, radius_texels, size, uv_name):
        """The brush ring there: (world centre, world unit normal, world radius)."""
        m = self.ob.matrix_world
        world_r = texel_world_size(self.evaluated, self.evaluated.data, self.index, uv_name, size) * radius_texels
        return m @ self.co, (m.to_3x3() @ self.normal).normalized(), world_r


def surface_hit(context, ob, origin, direction):
    """Cast a world-space ray at the evaluated (displaced) ``ob``: a `Hit`, or None."""
    depsgraph = context.evaluated_depsgraph_get()
    evaluated = ob.evaluated_get(depsgraph)
    inv = ob.matrix_world.inverted()
    hit, co, normal, index = evaluated.ray_cast(inv @ mathutils.Vector(origin),
                                                (inv.to_3x3() @ mathutils.Vector(direction)).normalized(),
                                                depsgraph=depsgraph)
    return Hit(ob, evaluated, co, normal, index) if hit else None


def mouse_hit(context, ob, mouse):
    """`surface_hit` for a mouse position in region pixels, or None."""
    from bpy_extras import view3d_utils

    region, rv3d = context.region, context.region_data
    if region is None or rv3d is None:
        return None
    origin = view3d_utils.region_2d_to_origin_3d(region, rv3d, mouse)
    direction = view3d_utils.region_2d_to_vector_3d(region, rv3d, mouse)
    return surface_hit(context, ob, origin, direction)


def ring_points(centre, normal, radius, segments=48):
    """(segments + 1, 3) float32 points of a closed circle."""
    t = normal.orthogonal().normalized()
    b = normal.cross(t)
    a = np.linspace(0.0, 2.0 * math.pi, segments + 1)[:, None]
    c, t, b = np.array(centre), np.array(t), np.array(b)
    return (c + radius * (np.cos(a) * t + np.sin(a) * b)).astype(np.float32)


def draw_ring(ring, color=(1.0, 0.55, 0.1, 1.0)):
    """Draw a ring (centre, normal, radius) in the current 3D view."""
    import gpu
    from gpu_extras.batch import batch_for_shader

    shader = gpu.shader.from_builtin("UNIFORM_COLOR")
    batch = batch_for_shader(shader, "LINE_STRIP", {"pos": ring_points(*ring)})
    shader.uniform_float("color", color)
    gpu.state.line_width_set(2.0)
    batch.draw(shader)
    gpu.state.line_width_set(1.0)


def brush_ring_at(context, mouse):
    """The active object's brush ring under the mouse, or None (no map, nothing hit, no UV map)."""
    ob = context.active_object
    if ob is None or ob.type != "MESH" or ob.tessera.displacement.image is None:
        return None
    hit = mouse_hit(context, ob, mouse)
    if hit is None:
        return None
    settings = ob.tessera.displacement
    try:
        return hit.ring(context.scene.tessera.brush.radius, tuple(settings.image.size), settings.uv_map)
    except (TesseraError, AttributeError):
        return None


#: Strokes so far and whether one is running: the hover ring hides while the stroke draws its own, and a ring from
#: before a stroke is never drawn again (Blender does not move gizmos while a modal operator runs).
STROKES = {"count": 0, "running": False}


def stroke_started():
    STROKES["count"] += 1
    STROKES["running"] = True


def stroke_ended():
    STROKES["running"] = False


class TESSERA_GT_brush_cursor(bpy.types.Gizmo):
    """Follows the mouse (``test_select`` is called on every move) and draws the brush ring; never selects. Only
    one ring is ever drawn: none while a stroke draws its own, none left where a stroke began."""

    bl_idname = "TESSERA_GT_brush_cursor"

    def setup(self):
        self.ring, self.strokes = None, STROKES["count"]

    def test_select(self, context, location):
        ring = brush_ring_at(context, location)
        if ring != self.ring or self.strokes != STROKES["count"]:
            self.ring, self.strokes = ring, STROKES["count"]
            context.area.tag_redraw()
        return -1

    def draw(self, context):
        if self.ring is not None and not STROKES["running"] and self.strokes == STROKES["count"]:
            draw_ring(self.ring, color=(1.0, 0.55, 0.1, 0.6))


class TESSERA_GGT_brush_cursor(bpy.types.GizmoGroup):
    bl_idname = "TESSERA_GGT_brush_cursor"
    bl_label = "Displacement Brush Cursor"
    bl_space_type = "VIEW_3D"
    bl_region_type = "WINDOW"
    bl_options = {"3D"}

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        return ob is not None and ob.type == "MESH" and ob.tessera.displacement.image is not None

    def setup(self, context):
        self.cursor = self.gizmos.new(TESSERA_GT_brush_cursor.bl_idname)


classes = (TESSERA_GT_brush_cursor, TESSERA_GGT_brush_cursor)
register, unregister = bpy.utils.register_classes_factory(classes)

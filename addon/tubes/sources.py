"""Centre lines for tubes from a Blender object: a Curve, hair Curves, or a mesh's edges (object space)."""

import numpy as np

from ...kernels.common.curves import nurbs
from ...kernels.common.curves.bezier_curves import CurveSampling, adaptive_nurbs, adaptive_spline
from ...kernels.common.errors import InvalidInputError
from ...kernels.tubes.edge_chains import chains_from_edges
from ...kernels.tubes.polylines import Polylines
from .. import bridge, curve_bridge

SOURCE_TYPES = {"CURVE", "CURVES", "MESH"}


def read_lines(ob, settings):
    """`Polylines` and notes for ``ob`` with the radius chosen in ``settings`` (operator or property group)."""
    notes, vertex_ids = [], None
    if ob.type == "CURVE" and settings.curve_sampling == "CURVATURE":
        lines = _curvature_lines(ob, settings)
    elif ob.type == "CURVE":
        lines, notes = curve_bridge.read_curve_object(ob, settings.radius)  # point radius x Radius, like a bevel
    elif ob.type == "CURVES":
        lines = curve_bridge.read_hair_curves(ob.data, settings.radius)  # the 'radius' attribute where present
    elif ob.type == "MESH":
        positions, edges = bridge.read_wire_mesh(ob.data)
        lines, vertex_ids = chains_from_edges(positions, edges)
        lines.radius[:] = settings.radius
    else:
        raise InvalidInputError(f"{ob.name!r} is not a curve, hair curves or mesh object")
    if settings.radius_source == "CONSTANT":
        lines.radius[:] = settings.radius
    elif settings.radius_source == "ATTRIBUTE":
        if ob.type == "CURVE":
            raise InvalidInputError(f"{ob.name!r} is a curve object: its radius comes From Points")
        count = len(ob.data.vertices) if ob.type == "MESH" else len(lines.points)
        values = bridge.point_float_attribute(ob.data, settings.attribute, count)
        lines.radius[:] = (values if vertex_ids is None else values[vertex_ids]) * settings.radius
    return lines, notes


def _curvature_lines(ob, settings):
    """A Curve object's centre lines with each Bézier segment and each NURBS piece sampled by its curvature (eq.
    4.5; poly splines as they are), radius (x Radius, like a bevel) and tilt along each segment."""
    sampling = CurveSampling(mode="CURVATURE", max_segments=settings.max_segments)
    points, radius, tilt, counts, cyclic, materials = [], [], [], [], [], []
    for sp in curve_bridge.read_splines(ob.data, ob.name):
        if sp.kind == "BEZIER" and len(sp.co) >= 2:
            [a] = adaptive_spline(sp.co, sp.handle_left, sp.handle_right, sp.radius, sp.tilt, sp.cyclic, sampling)
            pts, rad, til = a.points, a.radius, a.tilt
        elif sp.kind == "NURBS" and len(sp.co) >= 2:
            [a] = adaptive_nurbs(sp.co, sp.weight, nurbs.Direction(sp.order, sp.knot_mode, sp.cyclic), sp.radius,
                                 sp.tilt, sampling)
            pts, rad, til = a.points, a.radius, a.tilt
        elif sp.kind == "POLY":
            pts, rad, til = sp.co, sp.radius, sp.tilt
        else:
            raise InvalidInputError(f"Curve {ob.name!r} has a spline of a single point: delete it or add points")
        points.append(pts)
        radius.append(rad * settings.radius)
        tilt.append(til)
        counts.append(len(pts))
        cyclic.append(sp.cyclic)
        materials.append(sp.material_index)
    if not points:
        raise InvalidInputError(f"Curve {ob.name!r} has no points: add a spline, or select another curve")
    return Polylines.build(np.concatenate(points), np.concatenate([[0], np.cumsum(counts)]), np.concatenate(radius),
                           np.concatenate(tilt), cyclic, materials)

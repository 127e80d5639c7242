"""Centre lines for tubes from a Blender object: a Curve, hair Curves, or a mesh's edges (object space)."""

from ...kernels.common.errors import InvalidInputError
from ...kernels.tubes.edge_chains import chains_from_edges
from .. import bridge

SOURCE_TYPES = {"CURVE", "CURVES", "MESH"}


def read_lines(ob, settings):
    """`Polylines` and notes for ``ob`` with the radius chosen in ``settings`` (operator or property group)."""
    notes, vertex_ids = [], None
    if ob.type == "CURVE":
        lines, notes = bridge.read_curve_object(ob, settings.radius)  # point radius x Radius, like a bevel
    elif ob.type == "CURVES":
        lines = bridge.read_hair_curves(ob.data, settings.radius)  # the 'radius' attribute where present
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

"""Curve data across the bpy boundary: legacy Curve objects (evaluated centre lines for tubes, control points of
Bézier / poly / NURBS splines, new poly curves), hair `Curves`, and the NURBS splines of surface objects. Mesh and pixel
data stay in `bridge`."""

from dataclasses import dataclass

import bpy
import numpy as np

from ..kernels.common.curves import nurbs
from ..kernels.common.errors import EmptyResultError, InvalidInputError
from ..kernels.common.limits import MAX_WORLD_VALUE
from .bridge import _get


def _control_values(spline, name):
    points = spline.bezier_points if spline.type == "BEZIER" else spline.points
    values = np.empty(len(points), np.float32)
    points.foreach_get(name, values)
    return values.astype(np.float64)


def read_curve_object(ob, radius_scale=1.0):
    """Evaluated centre lines of a legacy Curve object (poly, Bézier, NURBS) as `Polylines` in object space.

    Points come from Blender's own evaluation (resolution, handles, NURBS order) of a bevel-free copy;
    radius (x ``radius_scale``) and tilt are the control points' values spread over the evaluated points.
    Returns ``(lines, notes)``.
    """
    from ..kernels.tubes.curve_sampling import spread_over_points, wire_runs
    from ..kernels.tubes.polylines import Polylines

    data = ob.data.copy()
    probe = bpy.data.objects.new("__tessera_curve_probe", data)
    notes = []
    try:
        data.bevel_depth, data.extrude, data.bevel_object, data.taper_object = 0.0, 0.0, None, None
        wire = probe.to_mesh()  # None for a curve without splines
        n_v = len(wire.vertices) if wire is not None else 0
        if n_v == 0:
            raise EmptyResultError(f"Curve {ob.name!r} has no points: add a spline, or select another curve")
        positions = _get(wire.attributes["position"].data, "vector", n_v, np.float32, 3)
        edges = _get(wire.edges, "vertices", len(wire.edges), np.int32, 2)
        counts, cyclic = wire_runs(n_v, edges)
        splines = [s for s in data.splines if len(s.bezier_points if s.type == "BEZIER" else s.points) > 0]
        radius = np.full(n_v, radius_scale)
        tilt = np.zeros(n_v)
        materials = np.zeros(len(counts), np.int32)
        if len(splines) == len(counts):
            off = np.concatenate(([0], np.cumsum(counts)))
            for i, s in enumerate(splines):
                span = slice(off[i], off[i + 1])
                radius[span] = radius_scale * spread_over_points(_control_values(s, "radius"), counts[i], cyclic[i])
                tilt[span] = spread_over_points(_control_values(s, "tilt"), counts[i], cyclic[i])
                materials[i] = s.material_index
        else:
            notes.append(f"Curve {ob.name!r}: the evaluated splines do not match the control splines; "
                         "point radius and tilt were not carried over")
        lines = Polylines.build(positions, np.concatenate(([0], np.cumsum(counts))), radius, tilt, cyclic,
                                materials)
    finally:
        probe.to_mesh_clear()
        bpy.data.objects.remove(probe)
        bpy.data.curves.remove(data)
    return lines, notes


@dataclass
class SplineArrays:
    """One spline of a Curve data-block: kind ``BEZIER``, ``POLY`` or ``NURBS``; co (n, 3) float64; handle_left and
    handle_right (n, 3) float64 (Bézier) or None; radius and tilt (n,) float64; cyclic; material_index; weight (n,)
    float64, order and knot_mode (one of `kernels.common.curves.nurbs.KNOT_MODES`) for NURBS, else None, 0, ""."""

    kind: str
    co: np.ndarray
    handle_left: np.ndarray | None
    handle_right: np.ndarray | None
    radius: np.ndarray
    tilt: np.ndarray
    cyclic: bool
    material_index: int = 0
    weight: np.ndarray | None = None
    order: int = 0
    knot_mode: str = ""


def _check_points(name, k, *arrays):
    """Refuse spline ``k`` of the curve object ``name`` when a point (or handle, or weight) is at NaN, infinity or
    beyond `MAX_WORLD_VALUE`."""
    for values in arrays:
        if values is None:
            continue
        bad = ~(np.abs(values.reshape(len(values), -1)) <= MAX_WORLD_VALUE).all(axis=1)
        if bad.any():
            raise InvalidInputError(f"Spline {k} of {name!r} has a point at NaN, infinity or beyond "
                                    f"{MAX_WORLD_VALUE:g} (point {int(np.argmax(bad))}): move or delete it")


def read_splines(curve, name=None):
    """The control points of every spline of a `bpy.types.Curve` as `SplineArrays` (object space); ``name``: the
    object's, for messages (default: the curve's)."""
    out = []
    for k, s in enumerate(curve.splines):
        bezier = s.type == "BEZIER"
        points = s.bezier_points if bezier else s.points
        n = len(points)
        if n == 0:
            continue
        if bezier:
            co = _get(points, "co", n, np.float32, 3).astype(np.float64)
            hl = _get(points, "handle_left", n, np.float32, 3).astype(np.float64)
            hr = _get(points, "handle_right", n, np.float32, 3).astype(np.float64)
        else:
            co4 = _get(points, "co", n, np.float32, 4).astype(np.float64)
            co, hl, hr = co4[:, :3], None, None
        _check_points(name or curve.name, k, co4 if not bezier else co, hl, hr)
        nurbs_spline = s.type == "NURBS"
        out.append(SplineArrays(s.type, co, hl, hr, _control_values(s, "radius"), _control_values(s, "tilt"),
                                bool(s.use_cyclic_u), s.material_index,
                                co4[:, 3] if nurbs_spline else None, s.order_u if nurbs_spline else 0,
                                nurbs.knot_mode(s.use_endpoint_u, s.use_bezier_u) if nurbs_spline else ""))
    return out


def read_surface_splines(curve, name=None):
    """The NURBS splines of a SURFACE curve, in object space: ``(surfaces, rows)``. surfaces: (index,
    `kernels.common.curves.nurbs.SurfaceSpline`) for each spline with more than one point in both directions
    (points (nv, nu, 4), u fastest in Blender's list); rows: (index, points (n, 4), `Direction`) for each spline
    that is a single row (Add > Surface > NURBS Curve or Circle), a curve drawn as edges. ``name``: the object's, for
    messages."""
    surfaces, rows = [], []
    for k, s in enumerate(curve.splines):
        nu, nv = s.point_count_u, s.point_count_v
        co = _get(s.points, "co", len(s.points), np.float32, 4).astype(np.float64)
        _check_points(name or curve.name, k, co)
        u = nurbs.Direction(s.order_u, nurbs.knot_mode(s.use_endpoint_u, s.use_bezier_u), bool(s.use_cyclic_u))
        if nv <= 1 or nu <= 1:
            if nu <= 1:
                u = nurbs.Direction(s.order_v, nurbs.knot_mode(s.use_endpoint_v, s.use_bezier_v),
                                    bool(s.use_cyclic_v))
            rows.append((k, co, u))
            continue
        v = nurbs.Direction(s.order_v, nurbs.knot_mode(s.use_endpoint_v, s.use_bezier_v), bool(s.use_cyclic_v))
        surfaces.append((k, nurbs.SurfaceSpline(co.reshape(nv, nu, 4), u, v)))
    return surfaces, rows


def write_poly_curve(name, splines, dimensions="3D"):
    """A new `bpy.types.Curve` of POLY splines from `SplineArrays` (their co, radius, tilt, cyclic and material;
    handles ignored). Removed again if anything fails."""
    data = bpy.data.curves.new(name, "CURVE")
    try:
        data.dimensions = dimensions
        for sp in splines:
            s = data.splines.new("POLY")
            n = len(sp.co)
            s.points.add(n - 1)
            s.points.foreach_set("co", np.c_[sp.co, np.ones(n)].astype(np.float32).ravel())
            s.points.foreach_set("radius", np.asarray(sp.radius, np.float32))
            s.points.foreach_set("tilt", np.asarray(sp.tilt, np.float32))
            s.use_cyclic_u, s.material_index = sp.cyclic, sp.material_index
    except BaseException:
        bpy.data.curves.remove(data)
        raise
    return data


def read_hair_curves(curves, default_radius):
    """Points of a hair `Curves` data-block as `Polylines` in object space.

    Radius from the ``radius`` point attribute, or ``default_radius`` where the curves have none.
    """
    from ..kernels.tubes.polylines import Polylines

    n_p, n_c = len(curves.points), len(curves.curves)
    if n_p == 0:
        raise InvalidInputError(f"Curves {curves.name!r} has no points")
    positions = _get(curves.attributes["position"].data, "vector", n_p, np.float32, 3)
    offsets = _get(curves.curve_offset_data, "value", n_c + 1, np.int32)
    attr = curves.attributes.get("radius")
    has_radius = attr is not None and attr.domain == "POINT" and attr.data_type == "FLOAT"
    radius = _get(attr.data, "value", n_p, np.float32) if has_radius else default_radius
    cyc = curves.attributes.get("cyclic")
    cyclic = _get(cyc.data, "value", n_c, bool) if cyc is not None and cyc.domain == "CURVE" else False
    mat = curves.attributes.get("material_index")
    materials = _get(mat.data, "value", n_c, np.int32) if mat is not None and mat.domain == "CURVE" else None
    return Polylines.build(positions, offsets, radius, None, cyclic, materials)

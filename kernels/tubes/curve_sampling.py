"""Evaluated curves back to their splines: the runs of a curve's evaluated wire mesh, and control-point values
(radius, tilt) spread over the evaluated points, as Blender's bevel spreads them."""

import numpy as np


def wire_runs(n_verts, edges):
    """Point counts and cyclic flags of the consecutive-vertex runs of a curve's wire mesh.

    Blender evaluates each spline of a curve object into consecutive vertices joined by edges ``i, i + 1``, and a
    cyclic spline adds one closing edge from its last vertex back to its first. n_verts: V; edges: (E, 2) int.
    Returns ``(counts (R,) int64, cyclic (R,) bool)``, runs in vertex order.
    """
    a, b = edges[:, 0].astype(np.int64), edges[:, 1].astype(np.int64)
    linked = np.zeros(n_verts, bool)  # linked[i]: an edge joins i and i + 1
    step = np.abs(a - b) == 1
    linked[np.minimum(a, b)[step]] = True
    breaks = np.nonzero(~linked[:-1])[0] + 1
    starts = np.concatenate(([0], breaks))
    stops = np.concatenate((breaks, [n_verts]))
    closing = {(int(min(x, y)), int(max(x, y))) for x, y in zip(a[~step], b[~step], strict=True)}
    cyclic = np.array([(int(s), int(e - 1)) in closing for s, e in zip(starts, stops, strict=True)], bool)
    return stops - starts, cyclic


def spread_over_points(values, count, cyclic):
    """Control-point values spread linearly over ``count`` evaluated points (exact for poly and Bézier).

    values: (n,) float64 per control point; cyclic: the spline closes, so the last span runs back to the first
    point. Returns (count,) float64.
    """
    n = len(values)
    if n == 1 or count == 1:
        return np.full(count, values[0])
    if cyclic:
        u = np.arange(count) * n / count
        return np.interp(u, np.arange(n + 1), np.append(values, values[0]))
    return np.interp(np.arange(count) * (n - 1) / (count - 1), np.arange(n), values)

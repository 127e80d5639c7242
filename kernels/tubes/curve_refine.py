"""Preparing tube centre lines ([Nunes 2011, §4.3.1]): Catmull-Rom refinement and tolerance-based point selection.

Both work on all curves at once. Refinement turns sparse control points ("the bad case": a path the tube
must pass through) into a dense centre line; selection keeps a point only where the tangent has turned by
another ``angle`` (or the radius has changed by another ``radius_change``), so straight runs cost two
points however many the input had.
"""

import numpy as np

from ..common.errors import InvalidInputError
from ..common.tolerances import FLOAT64_TINY
from .polylines import Polylines, next_index

CATMULL_ROM = ("UNIFORM", "CENTRIPETAL")


def catmull_rom(lines, subdivisions, kind="CENTRIPETAL"):
    """Catmull-Rom spline through every point, ``subdivisions`` segments per input segment.

    The spline interpolates the input points (they appear unchanged in the output); open ends use mirrored
    phantom points, closed curves wrap. ``kind``: UNIFORM (alpha 0) or CENTRIPETAL (alpha 0.5, no cusps or
    self-intersections inside a segment). Radius and tilt are interpolated linearly. Needs distinct
    consecutive points. Returns new `Polylines`.
    """
    if kind not in CATMULL_ROM:
        raise InvalidInputError(f"Catmull-Rom kind must be one of {CATMULL_ROM}; got {kind!r}")
    n_sub = int(subdivisions)
    if n_sub < 1:
        raise InvalidInputError("Catmull-Rom subdivisions must be at least 1")
    if n_sub == 1 or len(lines.points) == 0:
        return lines
    alpha = 0.5 if kind == "CENTRIPETAL" else 0.0
    pts = lines.points
    nxt = next_index(lines)
    seg = np.nonzero(nxt >= 0)[0]  # segment i runs from point seg[i] to nxt[seg[i]]
    i1, i2 = seg, nxt[seg]
    prev = np.full(len(pts), -1, np.int64)
    prev[i2] = i1
    p1, p2 = pts[i1], pts[i2]
    p0 = np.where((prev[i1] >= 0)[:, None], pts[np.maximum(prev[i1], 0)], 2 * p1 - p2)
    i3 = nxt[i2]
    p3 = np.where((i3 >= 0)[:, None], pts[np.maximum(i3, 0)], 2 * p2 - p1)

    # Barry-Goldman pyramid with knots t0=0, t1, t2, t3 from chord lengths ** alpha
    def knot(a, b):
        return np.maximum(np.linalg.norm(b - a, axis=1), FLOAT64_TINY) ** alpha

    k1 = knot(p0, p1)
    k2 = k1 + knot(p1, p2)
    k3 = k2 + knot(p2, p3)
    s = np.arange(n_sub) / n_sub  # samples of each segment, its end point belongs to the next segment
    t = k1[:, None] + s[None, :] * (k2 - k1)[:, None]  # (S, n)
    k0 = np.zeros_like(k1)

    p0, p1, p2, p3 = (p[:, None] for p in (p0, p1, p2, p3))  # (S, 1, 3) against the (S, n) samples
    a1 = _lerp_pyramid(p0, p1, t, k0, k1)
    a2 = _lerp_pyramid(p1, p2, t, k1, k2)
    a3 = _lerp_pyramid(p2, p3, t, k2, k3)
    b1 = _lerp_pyramid(a1, a2, t, k0, k2)
    b2 = _lerp_pyramid(a2, a3, t, k1, k3)
    c = _lerp_pyramid(b1, b2, t, k1, k2)
    c[:, 0] = p1[:, 0]  # exactly the input point

    curve_of_seg = lines.curve_of_point()[i1]
    counts = np.bincount(curve_of_seg, minlength=lines.n_curves) * n_sub
    open_end = ~lines.cyclic & (lines.counts > 0)
    counts += open_end  # the last input point of an open curve
    # interleave: each curve's segment samples, then its last point if open
    out_pts = np.empty((int(counts.sum()), 3))
    offsets = np.concatenate(([0], np.cumsum(counts)))
    seg_local = np.arange(len(seg)) - np.searchsorted(seg, lines.offsets[:-1])[curve_of_seg]
    dest = offsets[curve_of_seg][:, None] + seg_local[:, None] * n_sub + np.arange(n_sub)[None, :]
    out_pts[dest.ravel()] = c.reshape(-1, 3)
    ends = np.nonzero(open_end)[0]
    out_pts[offsets[ends + 1] - 1] = pts[lines.offsets[ends + 1] - 1]

    def per_point(values):
        out = np.empty(len(out_pts))
        out[dest.ravel()] = ((1 - s)[None, :] * values[i1][:, None] + s[None, :] * values[i2][:, None]).ravel()
        out[offsets[ends + 1] - 1] = values[lines.offsets[ends + 1] - 1]
        return out

    return Polylines(out_pts, offsets, per_point(lines.radius), per_point(lines.tilt), lines.cyclic.copy(),
                     lines.material_index.copy(), list(lines.notes))


def _lerp_pyramid(pa, pb, t, ta, tb):
    """One level of the Barry-Goldman pyramid: blend pa -> pb as t (S, n) runs from ta to tb (S,)."""
    w = ((t - ta[:, None]) / (tb - ta)[:, None])[..., None]
    return (1 - w) * pa + w * pb


def turning_angles(lines):
    """Angle (radians) between the incoming and outgoing segment at each point, 0 at open ends: (P,)."""
    pts = lines.points
    nxt = next_index(lines)
    has_next = nxt >= 0
    d = np.zeros_like(pts)
    d[has_next] = pts[nxt[has_next]] - pts[has_next]
    d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), FLOAT64_TINY)
    prev = np.full(len(pts), -1, np.int64)
    prev[nxt[has_next]] = np.nonzero(has_next)[0]
    ok = (prev >= 0) & has_next
    ang = np.zeros(len(pts))
    cosang = np.clip(np.sum(d[prev[ok]] * d[ok], axis=1), -1.0, 1.0)
    ang[ok] = np.arccos(cosang)
    return ang


def select_points(lines, angle, radius_change=0.05):
    """Keep the points where the tangent has turned by another ``angle`` radians (or the relative radius has
    changed by another ``radius_change``) since the curve start; always keep open ends.

    Every point whose turning angle alone is at least ``angle`` is kept, so corners survive; on a straight
    run of constant radius only the ends remain. ``angle <= 0`` keeps everything. Returns new `Polylines`.
    """
    if angle <= 0 or len(lines.points) == 0:
        return lines
    curve = lines.curve_of_point()
    turn = turning_angles(lines)
    scale = np.maximum(lines.radius, FLOAT64_TINY)
    nxt = next_index(lines)
    dr = np.zeros(len(turn))
    ok = nxt >= 0
    dr[ok] = np.abs(lines.radius[nxt[ok]] - lines.radius[ok]) / scale[ok]
    keep = np.zeros(len(turn), bool)
    for values, tol in ((turn, angle), (np.concatenate(([0.0], dr[:-1])), radius_change)):
        if tol <= 0:
            continue
        csum = np.cumsum(values)
        base = np.concatenate(([0.0], csum))[lines.offsets[:-1]][curve]
        level = np.floor((csum - base) / tol)
        prev_level = np.floor((csum - values - base) / tol)
        keep |= level > prev_level
    keep |= turn >= angle
    firsts = lines.offsets[:-1][lines.counts > 0]
    keep[firsts] = True
    open_last = lines.offsets[1:][(lines.counts > 0) & ~lines.cyclic] - 1
    keep[open_last] = True
    out = lines.subset(keep)
    out.cyclic = out.cyclic & (out.counts >= 3)
    return out

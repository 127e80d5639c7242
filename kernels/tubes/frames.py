"""Rotation-minimising frames along polylines: the double-reflection method (Wang et al. 2008).

One step of the method carries a frame from point ``i`` to ``i + 1`` with two reflections, so the step is
a rotation that depends only on the curve (points and tangents), not on the frame it carries. Each step
becomes a unit quaternion; the frame at point ``k`` is the first frame rotated by the product of the
steps before it, a prefix product computed for all curves at once with a segmented Hillis-Steele scan
(log2 of the longest curve passes). Closed curves spread the leftover angle at the seam along their
arc length, so the last segment meets the first without a twist.

Degenerate cases never produce NaN: duplicate points must be removed first (`polylines.drop_duplicates`),
a reversal of direction keeps the previous tangent, and a reflection whose plane is undefined is replaced
by one that acts identically on the frame vector.
"""

import numpy as np

from ..common.tolerances import FLOAT64_TINY, NO_DIRECTION
from .polylines import arc_lengths, next_index

_TINY = 1e-24


def _unit(v):
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.maximum(n, FLOAT64_TINY), n[..., 0]


def tangents(lines):
    """Unit tangents (P, 3) float64: the bisector of the adjacent segment directions, the segment at open ends.

    Needs distinct consecutive points. Where the curve reverses (bisector of zero length) the outgoing
    segment's direction is used.
    """
    pts = lines.points
    nxt = next_index(lines)
    prev = np.full(len(pts), -1, np.int64)
    has_next = nxt >= 0
    prev[nxt[has_next]] = np.nonzero(has_next)[0]
    out_dir = np.zeros_like(pts)
    out_dir[has_next] = _unit(pts[nxt[has_next]] - pts[has_next])[0]
    in_dir = np.zeros_like(pts)
    has_prev = prev >= 0
    in_dir[has_prev] = out_dir[prev[has_prev]]
    t, norm = _unit(in_dir + out_dir)
    reversed_ = norm < 1e-9
    t[reversed_] = np.where(has_next[reversed_, None], out_dir[reversed_], in_dir[reversed_])
    return t


def any_perpendicular(t):
    """A unit vector perpendicular to each unit vector in ``t`` (n, 3), continuous away from axis switches."""
    axis = np.zeros_like(t)
    axis[np.arange(len(t)), np.argmin(np.abs(t), axis=1)] = 1.0
    r = axis - np.sum(axis * t, axis=1, keepdims=True) * t
    return _unit(r)[0]


def _quat_mul(p, q):
    """Hamilton product p*q (apply q, then p) of (n, 4) quaternions (w, x, y, z)."""
    pw, px, py, pz = p.T
    qw, qx, qy, qz = q.T
    return np.stack((
        pw * qw - px * qx - py * qy - pz * qz,
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
    ), axis=1)


def rotate(q, v):
    """Rotate vectors v (n, 3) by unit quaternions q (n, 4)."""
    w, u = q[:, :1], q[:, 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def step_rotations(points, t0, t1):
    """Quaternions (n, 4) of the double-reflection steps from (points[i], t0[i]) to (points[i+1] ~ x1, t1[i]).

    points: (n, 2, 3) segment end points; t0, t1: (n, 3) unit tangents. Reflection 1 is across the plane
    normal to the chord, reflection 2 across the plane normal to ``t1 - t0'``. The product of reflections
    across unit normals a then b is the rotation (a.b, a x b).
    """
    a = _unit(points[:, 1] - points[:, 0])[0]
    t_l = t0 - 2.0 * np.sum(a * t0, axis=1, keepdims=True) * a
    b, nb = _unit(t1 - t_l)
    # reflection 2 undefined (t1 == reflected t0): reflecting across the plane normal to t1 acts on the frame
    # vector (already perpendicular to t1 after reflection 1) exactly like the identity
    flat = nb < NO_DIRECTION
    b[flat] = t1[flat]
    return np.concatenate((np.sum(a * b, axis=1, keepdims=True), np.cross(a, b)), axis=1)


def prefix_rotations(steps, offsets):
    """Segmented inclusive prefix product of quaternions.

    steps: (P, 4) where steps[k] carries point k-1 to k (steps at a curve's first point are ignored);
    offsets: (C + 1,) curve offsets. Returns (P, 4): the rotation carrying each curve's first frame to point k.
    """
    n = len(steps)
    acc = steps.copy()
    starts = offsets[:-1][np.diff(offsets) > 0]
    acc[starts] = (1.0, 0.0, 0.0, 0.0)
    local = np.arange(n) - np.repeat(offsets[:-1], np.diff(offsets))
    longest = int(local.max()) + 1 if n else 0
    d = 1
    while d < longest:
        # slices instead of index arrays: combine everything d apart, keep only pairs inside one curve
        inside = (local[d:] >= d)[:, None]
        acc[d:] = np.where(inside, _quat_mul(acc[d:], acc[:-d]), acc[d:])
        d *= 2
    # keep unit length against rounding drift of long products
    acc /= np.linalg.norm(acc, axis=1, keepdims=True)
    return acc


def rotation_minimizing_frames(lines, t=None):
    """Frames (T, N, B) at every point, each (P, 3) float64 unit, right-handed (B = T x N), twist-free.

    The first normal of each curve is perpendicular to its first tangent (`any_perpendicular`); the tilt
    (radians) rotates N and B about T; closed curves are corrected so the frame is continuous at the seam.
    """
    pts = lines.points
    t = tangents(lines) if t is None else t
    n = len(pts)
    if n == 0:
        empty = np.zeros((0, 3))
        return empty, empty, empty
    prev = np.arange(-1, n - 1)
    steps = np.zeros((n, 4))
    nonempty = lines.counts > 0
    firsts = lines.offsets[:-1][nonempty]
    inner = np.ones(n, bool)
    inner[firsts] = False
    k = np.nonzero(inner)[0]
    steps[k] = step_rotations(np.stack((pts[prev[k]], pts[k]), axis=1), t[prev[k]], t[k])
    q = prefix_rotations(steps, lines.offsets)
    r0 = any_perpendicular(t[firsts])  # each curve's first normal, carried along by its prefix rotations
    r = rotate(q, np.repeat(r0, lines.counts[nonempty], axis=0))
    # re-orthogonalise against the tangent (removes accumulated rounding)
    r = _unit(r - np.sum(r * t, axis=1, keepdims=True) * t)[0]

    angle = lines.tilt.copy()
    if np.any(lines.cyclic):
        angle += _seam_correction(lines, t, r, q)
    if np.any(angle):
        c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
        r = c * r + s * np.cross(t, r)
    b = np.cross(t, r)
    return t, r, b


def _seam_correction(lines, t, r, q):
    """Per-point angle (P,) that spreads each closed curve's seam twist along its arc length."""
    cyc = np.nonzero(lines.cyclic & (lines.counts >= 3))[0]
    out = np.zeros(len(t))
    if len(cyc) == 0:
        return out
    first = lines.offsets[cyc]
    last = lines.offsets[cyc + 1] - 1
    pts = lines.points
    step = step_rotations(np.stack((pts[last], pts[first]), axis=1), t[last], t[first])
    r_end = rotate(step, r[last])  # the frame carried all the way round, back at the first point
    r_end = _unit(r_end - np.sum(r_end * t[first], axis=1, keepdims=True) * t[first])[0]
    phi = np.arctan2(np.sum(np.cross(r_end, r[first]) * t[first], axis=1), np.sum(r_end * r[first], axis=1))
    arc, total = arc_lengths(lines)
    curve = lines.curve_of_point()
    per_curve = np.zeros(lines.n_curves)
    per_curve[cyc] = phi / np.maximum(total[cyc], _TINY)
    return per_curve[curve] * arc


def rotation_minimizing_frames_opencl(runtime, lines, arc, total, out=None):
    """The same frames from ``kernels/tubes/tube_frames.cl`` (one work item per curve): t, n, b (P, 3) float32.

    arc, total: from `polylines.arc_lengths`; out: three contiguous (P, 3) float32 arrays to write into, or
    None. Needs double precision on the device. Host memory is shared with the device (``USE_HOST_PTR``: no
    copies on a CPU device such as PoCL).
    """
    n_pts, n_curves = len(lines.points), lines.n_curves
    if out is None:
        out = [np.empty((n_pts, 3), np.float32) for _ in range(3)]
    if n_pts == 0:
        return tuple(out)
    inputs = [np.ascontiguousarray(a, dtype) for a, dtype in (
        (lines.points, np.float64), (lines.offsets, np.int64), (lines.cyclic, np.uint8), (lines.tilt, np.float64),
        (arc, np.float64), (total, np.float64))]
    outs = [runtime.shared(o) for o in out]
    kernel = runtime.kernel("tubes/tube_frames", "tube_frames")
    kernel(runtime.queue, (n_curves,), None, *(runtime.shared(a, read_only=True) for a in inputs), *outs,
           np.int32(n_curves))
    runtime.sync_to_host(zip(outs, out, strict=True))
    return tuple(out)


def has_fp64(runtime):
    return runtime is not None and "cl_khr_fp64" in runtime.device.extensions

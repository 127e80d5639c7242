"""Many polylines as flat arrays (points + offsets), the input of the tube kernels.

Curve ``c`` owns points ``offsets[c]:offsets[c + 1]``. Everything here is vectorised over all curves at
once: per-point helpers come from `np.repeat` over the curve lengths, never from a Python loop per point.
"""

from dataclasses import dataclass, field, replace

import numpy as np

from ..common import workers
from ..common.errors import InvalidInputError

#: Consecutive points closer than this (relative to the curve set's extent) are duplicates.
DUPLICATE_REL = 1e-9


@dataclass
class Polylines:
    """Polylines with per-point radius and tilt.

    points: (P, 3) float64; offsets: (C + 1,) int64, non-decreasing, offsets[0] = 0, offsets[-1] = P;
    radius: (P,) float64 >= 0; tilt: (P,) float64 radians about the tangent;
    cyclic: (C,) bool, a closed curve joins its last point to its first;
    material_index: (C,) int32 per curve (copied to the curve's faces).
    """

    points: np.ndarray
    offsets: np.ndarray
    radius: np.ndarray
    tilt: np.ndarray = None
    cyclic: np.ndarray = None
    material_index: np.ndarray = None
    notes: list = field(default_factory=list)

    @classmethod
    def build(cls, points, offsets, radius=1.0, tilt=None, cyclic=False, material_index=None):
        """Validate and normalise the inputs; scalars broadcast. Raises `InvalidInputError`."""
        pts = np.asarray(points, np.float64).reshape(-1, 3)
        off = np.asarray(offsets, np.int64).ravel()
        if off.ndim != 1 or len(off) < 1 or off[0] != 0 or off[-1] != len(pts) or np.any(np.diff(off) < 0):
            raise InvalidInputError("Curve offsets must start at 0, never decrease and end at the point count")
        if not np.all(np.isfinite(pts)):
            bad = int(np.argmax(~np.all(np.isfinite(pts), axis=1)))
            raise InvalidInputError(f"Curve point {bad} is NaN or infinite")
        n_curves = len(off) - 1
        rad = np.broadcast_to(np.asarray(radius, np.float64), (len(pts),)).copy()
        if not np.all(np.isfinite(rad)) or np.any(rad < 0):
            raise InvalidInputError("Curve radii must be finite and not negative")
        til = np.zeros(len(pts)) if tilt is None else np.broadcast_to(np.asarray(tilt, np.float64), (len(pts),)).copy()
        if not np.all(np.isfinite(til)):
            raise InvalidInputError("Curve tilt values must be finite")
        cyc = np.broadcast_to(np.asarray(cyclic, bool), (n_curves,)).copy()
        mat = np.zeros(n_curves, np.int32) if material_index is None else \
            np.broadcast_to(np.asarray(material_index, np.int32), (n_curves,)).copy()
        return cls(pts, off, rad, til, cyc, mat)

    @property
    def n_curves(self):
        return len(self.offsets) - 1

    @property
    def counts(self):
        """Points per curve: (C,) int64."""
        return np.diff(self.offsets)

    def curve_of_point(self):
        """Curve id of every point: (P,) int64."""
        return np.repeat(np.arange(self.n_curves), self.counts)

    def subset(self, keep_points):
        """The same curves with only the points where ``keep_points`` (P,) bool is True."""
        counts = np.bincount(self.curve_of_point(), weights=keep_points, minlength=self.n_curves).astype(np.int64)
        off = np.concatenate(([0], np.cumsum(counts)))
        return replace(self, points=self.points[keep_points], offsets=off, radius=self.radius[keep_points],
                       tilt=self.tilt[keep_points], notes=list(self.notes))

    def select_curves(self, keep_curves):
        """Only the curves where ``keep_curves`` (C,) bool is True."""
        return self.subset(np.repeat(keep_curves, self.counts)).drop_empty_curves(keep_curves)

    def drop_empty_curves(self, keep_curves):
        counts = self.counts[keep_curves]
        return replace(self, offsets=np.concatenate(([0], np.cumsum(counts))), cyclic=self.cyclic[keep_curves],
                       material_index=self.material_index[keep_curves])


def next_index(lines):
    """Index of the following point along the curve, wrapping on cyclic curves, -1 at open ends: (P,) int64."""
    n = len(lines.points)
    nxt = np.arange(1, n + 1, dtype=np.int64)
    ends = lines.offsets[1:][lines.counts > 0] - 1
    starts = lines.offsets[:-1][lines.counts > 0]
    cyc = lines.cyclic[lines.counts > 0]
    nxt[ends] = np.where(cyc, starts, -1)
    return nxt


def drop_duplicates(lines):
    """Remove consecutive duplicate points (and a cyclic curve's last point equal to its first).

    Curves left with fewer than two points are removed, with a note saying how many. Returns new `Polylines`.
    """
    pts = lines.points
    if len(pts) == 0:
        return lines
    extent = float(np.maximum(pts.max(), -pts.min())) + 1.0  # max |x|, without an (P, 3) temporary
    has_next = next_index(lines) >= 0
    seg = segment_lengths(lines)
    # a point is dropped when the segment leaving it has zero length; on an open curve the last point stays
    # and its predecessor goes instead
    dup = has_next & (seg <= DUPLICATE_REL * extent)
    out = lines.subset(~dup) if dup.any() else replace(lines, notes=list(lines.notes))
    keep_curves = out.counts >= 2
    removed = int(np.sum(~keep_curves))
    if removed:
        out = out.select_curves(keep_curves)
        out.notes.append(f"{removed} curve(s) with fewer than two distinct points were skipped")
    # a cyclic curve of two points is a doubled segment: treat it as open
    out.cyclic = out.cyclic & (out.counts >= 3)
    return out


def segment_lengths(lines):
    """Length of the segment leaving each point (0 at open ends): (P,) float64."""
    pts = np.asarray(lines.points, np.float64)
    seg = np.zeros(len(pts))
    if len(pts) < 2:
        return seg
    step = 1 << 15  # contiguous differences in blocks that stay in cache; the ends of curves are fixed below

    def blocks(first, last):
        for lo in range(first, last, step):
            hi = min(last, lo + step)
            d = pts[lo + 1 : hi + 1] - pts[lo:hi]
            np.sqrt(np.einsum("ij,ij->i", d, d), out=seg[lo:hi])

    # the blocks split between the worker threads (numpy lets go of the GIL); each value is computed as before
    n_seg = len(pts) - 1
    parts = workers.WORKERS if n_seg >= 4 * step else 1
    bounds = [n_seg * k // parts // step * step for k in range(parts)] + [n_seg]
    jobs = [workers.submit(blocks, lo, hi) for lo, hi in zip(bounds[:-1], bounds[1:], strict=True) if hi > lo]
    for job in jobs:
        job.result()
    nonempty = lines.counts > 0
    ends = lines.offsets[1:][nonempty] - 1
    starts = lines.offsets[:-1][nonempty]
    closing = pts[starts] - pts[ends]
    seg[ends] = np.where(lines.cyclic[nonempty], np.sqrt(np.einsum("ij,ij->i", closing, closing)), 0.0)
    return seg


def arc_lengths(lines):
    """Arc length from the curve start to each point (P,) and each curve's total length (C,).

    A cyclic curve's total includes its closing segment."""
    seg = segment_lengths(lines)
    csum = np.cumsum(seg)
    start_sum = np.concatenate(([0.0], csum))[lines.offsets[:-1]]
    curve = lines.curve_of_point()
    arc = csum - seg - start_sum[curve]
    total = np.bincount(curve, weights=seg, minlength=lines.n_curves)
    return arc, total


def chunks(lines, max_points=1 << 20):
    """Split into consecutive runs of whole curves with at most ``max_points`` points each (one curve may exceed it).

    Yields ``(first_curve, last_curve_exclusive)``.
    """
    c0 = 0
    n = lines.n_curves
    while c0 < n:
        limit = lines.offsets[c0] + max_points
        c1 = int(np.searchsorted(lines.offsets, limit, side="right")) - 1
        c1 = min(max(c1, c0 + 1), n)
        yield c0, c1
        c0 = c1


def take_curves(lines, c0, c1):
    """Curves ``c0:c1`` as their own `Polylines` (views where possible)."""
    p0, p1 = lines.offsets[c0], lines.offsets[c1]
    return Polylines(lines.points[p0:p1], lines.offsets[c0:c1 + 1] - p0, lines.radius[p0:p1], lines.tilt[p0:p1],
                     lines.cyclic[c0:c1], lines.material_index[c0:c1])

"""Cubic Bézier splines sampled where they bend ([Nellmedin 2014, §4.3 eq. 4.5, §5.5.2]): each segment gets its
own count of equal parameter steps, from the curvature of its control polygon (``max(6, min(32, 10 κ_max))``,
rounded up) or from a tolerance (world units, or pixels for a camera). Shared by the adaptive polyline operator
and the tubes.

A spline is its points and handles as Blender keeps them: segment i runs from point i (its right handle) to point
i + 1 (that point's left handle); a cyclic spline adds the segment from the last point back to the first. Samples
of consecutive segments share their end points, so the polyline is continuous and closes exactly on cyclic splines.

`adaptive_spline` samples a whole spline by a `CurveSampling` (curvature, world tolerance or pixels), with radius and
tilt interpolated along each segment and [Nellmedin 2014]'s "copies" (OL0, §5.5.2): N offset copies, for hair.
`adaptive_nurbs` does the same for a NURBS spline of any order, weights and knots, split exactly into rational Bézier
pieces (`kernels.common.curves.nurbs`): the curvature of each piece's control polygon, or a tolerance met by
measuring the chords (`kernels.common.curves.rational_bezier.tolerance_steps`).
"""

from dataclasses import dataclass

import numpy as np

from ..errors import InvalidInputError
from ..level_metrics import curvature_level, curve_kappa
from . import nurbs, step_spacing
from . import rational_bezier as rb

#: The curvature metric's cap on segments (eq. 4.5's t_tessmax) and its gain (one point per tenth of height).
MAX_SEGMENTS = 32
GAIN = 10.0
#: Most segments one span may get from a tolerance (a guard against tolerances far below the curve's size).
MAX_TOLERANCE_SEGMENTS = 1024


@dataclass
class SampledSpline:
    """points (n, 3) float64; segment (n,) int64 and t (n,) float64: the Bézier segment each sample lies on and
    its parameter there (so per-point values such as radius and tilt can be interpolated); counts (S,) int64
    segments per Bézier segment; cyclic: the polyline closes (its last point is not repeated)."""

    points: np.ndarray
    segment: np.ndarray
    t: np.ndarray
    counts: np.ndarray
    cyclic: bool


def segment_controls(co, handle_left, handle_right, cyclic):
    """Control polygons (S, 4, 3) of a spline's segments. co, handle_left, handle_right: (n, 3)."""
    co, hl, hr = (np.asarray(a, np.float64).reshape(-1, 3) for a in (co, handle_left, handle_right))
    n = len(co)
    if n < 2:
        return np.zeros((0, 4, 3))
    j = np.arange(n if cyclic else n - 1)
    k = (j + 1) % n
    return np.stack([co[j], hr[j], hl[k], co[k]], axis=1)


def curvature_counts(control, gain=GAIN, t_max=MAX_SEGMENTS):
    """Eq. 4.5 per segment, rounded up (equal spacing): (S, 4, 3) -> (S,) int64 in [6, t_max]."""
    return np.ceil(curvature_level(curve_kappa(control), n_control=4, gain=gain, t_max=t_max)).astype(np.int64)


def tolerance_counts(control, tolerance):
    """Segments so the polyline stays within ``tolerance`` of the curve: the chord of a step h deviates at most
    h² max|B''| / 8 from a curve whose second derivative is bounded by 6 max(|P0 - 2P1 + P2|, |P1 - 2P2 + P3|),
    so k = ceil(sqrt(3 M / (4 tolerance))). tolerance: a number or (S,) per segment (world units).
    Returns (S,) int64 in [1, MAX_TOLERANCE_SEGMENTS]."""
    c = np.asarray(control, np.float64)
    tol = np.broadcast_to(np.asarray(tolerance, np.float64), (len(c),))
    if not (np.all(np.isfinite(tol)) and np.all(tol > 0)):
        raise InvalidInputError("The curve tolerance must be a positive number")
    m = np.maximum(np.linalg.norm(c[:, 0] - 2 * c[:, 1] + c[:, 2], axis=1),
                   np.linalg.norm(c[:, 1] - 2 * c[:, 2] + c[:, 3], axis=1))
    return np.clip(np.ceil(np.sqrt(0.75 * m / tol)), 1, MAX_TOLERANCE_SEGMENTS).astype(np.int64)


def pixel_tolerance(control, camera, pixels):
    """World tolerance per segment for ``pixels`` on screen: the size of a pixel at the depth of the segment's
    nearest control point (its farthest point sets nothing: the near end needs the detail). camera: a
    `kernels.common.camera.Camera` in the curve's space. (S,) float64."""
    if not (np.isfinite(pixels) and pixels > 0):
        raise InvalidInputError(f"The tolerance in pixels must be a positive number; got {pixels!r}")
    c = np.asarray(control, np.float64)
    view, proj = np.asarray(camera.view, np.float64), np.asarray(camera.projection, np.float64)
    focal = 0.5 * camera.height * proj[1, 1]
    if camera.orthographic:
        return np.full(len(c), pixels / focal)
    depth = -(c @ view[2, :3] + view[2, 3])  # (S, 4) in front of the eye
    near = np.maximum(depth.min(axis=1), 1e-6 * (1.0 + np.abs(depth).max()))
    return pixels * near / focal


def evaluate(control, t):
    """Points of cubic segments: control (S, 4, 3), t (S, k) -> (S, k, 3) (Bernstein form)."""
    c = np.asarray(control, np.float64)
    t = np.asarray(t, np.float64)[..., None]
    s = 1.0 - t
    return (s * s * s * c[:, None, 0] + 3 * s * s * t * c[:, None, 1] + 3 * s * t * t * c[:, None, 2]
            + t * t * t * c[:, None, 3])


def steps(counts, cyclic):
    """Where a spline of segments split into counts (S,) equal steps is sampled: (segment (n,) int64, t (n,)
    float64); each segment from its start, the last end point once more unless the spline is cyclic."""
    counts = np.asarray(counts, np.int64)
    segment = np.repeat(np.arange(len(counts)), counts)
    first = np.repeat(np.cumsum(counts) - counts, counts)
    t = (np.arange(len(segment)) - first) / np.repeat(counts, counts)
    if not cyclic:
        segment, t = np.append(segment, len(counts) - 1), np.append(t, 1.0)
    return segment, t


def sample(control, counts, cyclic):
    """A `SampledSpline`: segment i split into counts[i] equal steps of t; shared ends written once."""
    c = np.asarray(control, np.float64)
    counts = np.asarray(counts, np.int64)
    if len(c) == 0:
        return SampledSpline(np.zeros((0, 3)), np.zeros(0, np.int64), np.zeros(0), counts, bool(cyclic))
    segment, t = steps(counts, cyclic)
    points = evaluate(c[segment], t[:, None])[:, 0]
    if not cyclic:
        points[-1] = c[-1, 3]
    return SampledSpline(points, segment, t, counts, bool(cyclic))


def offset_copies(points, copies, offset):
    """[Nellmedin 2014]'s OL0 (§5.5.2): ``copies`` polylines, copy k moved by ``offset * k / copies`` (k = 0 .. copies -
    1: the first is the curve itself). points: (n, 3) -> (copies, n, 3)."""
    if int(copies) != copies or copies < 1:
        raise InvalidInputError(f"Copies must be a whole number of at least 1; got {copies!r}")
    k = np.arange(int(copies), dtype=np.float64)[:, None, None] / copies
    return np.asarray(points, np.float64)[None] + k * np.asarray(offset, np.float64).reshape(1, 1, 3)


# --- whole splines: the sampling options, radius and tilt along, [Nellmedin 2014]'s copies ---------------------------

MODES = ("CURVATURE", "TOLERANCE", "SCREEN")


@dataclass(frozen=True)
class CurveSampling:
    """mode: CURVATURE (eq. 4.5: max(6, min(max_segments, 10 κ))), TOLERANCE (world units) or SCREEN (pixels, needs
    a camera); copies and offset: [Nellmedin 2014]'s OL0 (copy k moved by offset k / copies)."""

    mode: str = "CURVATURE"
    max_segments: int = MAX_SEGMENTS
    tolerance: float = 0.01
    pixels: float = 1.0
    copies: int = 1
    offset: tuple = (0.0, 0.0, 0.0)

    def __post_init__(self):
        if self.mode not in MODES:
            raise InvalidInputError(f"mode must be one of {', '.join(MODES)}; got {self.mode!r}")
        if not 6 <= self.max_segments <= MAX_TOLERANCE_SEGMENTS:
            raise InvalidInputError(f"Max Segments must be from 6 to {MAX_TOLERANCE_SEGMENTS}; got "
                                    f"{self.max_segments!r}")


@dataclass
class AdaptiveSpline:
    """One output polyline: points (n, 3), radius (n,), tilt (n,) float64, cyclic; counts (S,) segments per Bézier
    segment of its source; deviation (S,) float64: the largest distance measured between each segment and its
    chords (sampled to a tolerance or for the screen), else None."""

    points: np.ndarray
    radius: np.ndarray
    tilt: np.ndarray
    cyclic: bool
    counts: np.ndarray
    deviation: np.ndarray | None = None


def _world_tolerance(control, settings, camera):
    """The tolerance of TOLERANCE or SCREEN sampling in the curve's units: a number, or (S,) per segment for the
    screen (control (S, k, 3) the segments' control points)."""
    if settings.mode == "SCREEN":
        if camera is None:
            raise InvalidInputError("Sampling for the screen needs a camera")
        return pixel_tolerance(control, camera, settings.pixels)
    if not (np.isfinite(settings.tolerance) and settings.tolerance > 0):
        raise InvalidInputError("The curve tolerance must be a positive number")
    return settings.tolerance


def adaptive_spline(co, handle_left, handle_right, radius, tilt, cyclic, settings, camera=None):
    """Sample one Bézier spline (control points (n, 3), handles (n, 3), radius and tilt (n,)) by ``settings``
    (`CurveSampling`); camera: a `kernels.common.camera.Camera` in the spline's space, for SCREEN. Returns the
    `AdaptiveSpline` of each copy (a list of ``settings.copies``)."""
    control = segment_controls(co, handle_left, handle_right, cyclic)
    if len(control) == 0:
        raise InvalidInputError("A Bézier spline needs at least two points")
    deviation = None
    if settings.mode == "CURVATURE":
        counts = curvature_counts(control, t_max=settings.max_segments)
    else:
        counts = np.minimum(tolerance_counts(control, _world_tolerance(control, settings, camera)),
                            settings.max_segments)
        # the bound above meets the tolerance; what Max Segments leaves over it is measured, for the report
        deviation = rb.chord_deviation(np.concatenate([control, np.ones(control.shape[:2] + (1,))], -1), counts)
    s = sample(control, counts, cyclic)
    n = len(np.asarray(co))
    k = (s.segment + 1) % n

    def along(values):
        v = np.asarray(values, np.float64)
        return v[s.segment] + s.t * (v[k] - v[s.segment])

    r, tl = along(radius), along(tilt)
    return [AdaptiveSpline(p, r, tl, bool(cyclic), counts, deviation)
            for p in offset_copies(s.points, settings.copies, settings.offset)]


def adaptive_nurbs(co, weight, direction, radius, tilt, settings, camera=None, what="NURBS spline"):
    """Sample one NURBS spline (points (n, 3), weights (n,), a `kernels.common.curves.nurbs.Direction`, radius and tilt
    (n,)) by ``settings`` (`CurveSampling`), through its exact rational Bézier pieces. CURVATURE: eq. 4.5 on each
    piece's control polygon (a straight piece of order 2: one step); TOLERANCE and SCREEN: steps spaced where each
    piece bends, their count measured to meet the tolerance (up to Max Segments; the deviation left is in the
    result). what: how a refusal names the spline.
    Returns the `AdaptiveSpline` of each copy."""
    pts = np.c_[np.asarray(co, np.float64).reshape(-1, 3), np.asarray(weight, np.float64).reshape(-1)]
    pieces, _ = nurbs.curve_pieces(pts, direction, np.c_[radius, tilt], what=what)
    geo = pieces[..., :4]
    control = rb.cartesian(geo)
    deviation = None
    if settings.mode == "CURVATURE":
        if direction.order == 2:
            counts = np.ones(len(pieces), np.int64)
        else:
            counts = np.ceil(curvature_level(curve_kappa(control), n_control=direction.order, gain=GAIN,
                                             t_max=settings.max_segments)).astype(np.int64)
        segment, t = steps(counts, direction.cyclic)
    else:  # steps where each piece bends (`kernels.common.curves.step_spacing`)
        spacing = rb.curve_spacing(geo)
        counts, deviation = rb.tolerance_steps(geo, _world_tolerance(control, settings, camera), settings.max_segments,
                                               spacing=spacing)
        segment, t = steps(counts, direction.cyclic)
        k = np.rint(t * counts[segment]).astype(np.int64)  # each point's step in its piece
        t = step_spacing.padded_params(spacing, counts)[segment, k]
    h = np.einsum("nk,nkc->nc", rb.bernstein(t, direction.order - 1), pieces[segment])
    h[t == 0] = pieces[segment[t == 0], 0]  # piece ends exactly (shared by the pieces that meet there)
    if not direction.cyclic:
        h[-1] = pieces[-1, -1]
    points = h[:, :3] / h[:, 3:4]
    r, tl = h[:, 4] / h[:, 3], h[:, 5] / h[:, 3]
    return [AdaptiveSpline(p, r, tl, bool(direction.cyclic), counts, deviation)
            for p in offset_copies(points, settings.copies, settings.offset)]

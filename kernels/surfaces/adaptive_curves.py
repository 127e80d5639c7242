"""Curve to adaptive polyline (digest 001 §5.5.2 and §11.4): a Bézier spline sampled per segment by curvature
(eq. 4.5), by a world tolerance or by a tolerance in pixels for a camera (`kernels.common.bezier_curves`), with
radius and tilt interpolated along each segment, and the seed's "copies" (OL0): N offset copies of each spline,
for hair."""

from dataclasses import dataclass

import numpy as np

from ..common import bezier_curves as bz
from ..common.errors import InvalidInputError

MODES = ("CURVATURE", "TOLERANCE", "SCREEN")


@dataclass(frozen=True)
class CurveSampling:
    """mode: CURVATURE (eq. 4.5: max(6, min(max_segments, 10 κ))), TOLERANCE (world units) or SCREEN (pixels, needs
    a camera); copies and offset: the seed's OL0 (copy k moved by offset k / copies)."""

    mode: str = "CURVATURE"
    max_segments: int = bz.MAX_SEGMENTS
    tolerance: float = 0.01
    pixels: float = 1.0
    copies: int = 1
    offset: tuple = (0.0, 0.0, 0.0)

    def __post_init__(self):
        if self.mode not in MODES:
            raise InvalidInputError(f"mode must be one of {', '.join(MODES)}; got {self.mode!r}")
        if not 6 <= self.max_segments <= bz.MAX_TOLERANCE_SEGMENTS:
            raise InvalidInputError(f"Max Segments must be from 6 to {bz.MAX_TOLERANCE_SEGMENTS}; got "
                                    f"{self.max_segments!r}")


@dataclass
class AdaptiveSpline:
    """One output polyline: points (n, 3), radius (n,), tilt (n,) float64, cyclic; counts (S,) segments per Bézier
    segment of its source."""

    points: np.ndarray
    radius: np.ndarray
    tilt: np.ndarray
    cyclic: bool
    counts: np.ndarray


def adaptive_spline(co, handle_left, handle_right, radius, tilt, cyclic, settings, camera=None):
    """Sample one Bézier spline (control points (n, 3), handles (n, 3), radius and tilt (n,)) by ``settings``
    (`CurveSampling`); camera: a `kernels.common.camera.Camera` in the spline's space, for SCREEN. Returns the
    `AdaptiveSpline` of each copy (a list of ``settings.copies``)."""
    control = bz.segment_controls(co, handle_left, handle_right, cyclic)
    if len(control) == 0:
        raise InvalidInputError("A Bézier spline needs at least two points")
    if settings.mode == "CURVATURE":
        counts = bz.curvature_counts(control, t_max=settings.max_segments)
    else:
        if settings.mode == "SCREEN":
            if camera is None:
                raise InvalidInputError("Sampling for the screen needs a camera")
            tol = bz.pixel_tolerance(control, camera, settings.pixels)
        else:
            tol = settings.tolerance
        counts = np.minimum(bz.tolerance_counts(control, tol), settings.max_segments)
    s = bz.sample(control, counts, cyclic)
    n = len(np.asarray(co))
    k = (s.segment + 1) % n

    def along(values):
        v = np.asarray(values, np.float64)
        return v[s.segment] + s.t * (v[k] - v[s.segment])

    r, tl = along(radius), along(tilt)
    return [AdaptiveSpline(p, r, tl, bool(cyclic), counts) for p in bz.offset_copies(s.points, settings.copies,
                                                                                     settings.offset)]

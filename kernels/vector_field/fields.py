"""The steady 2-D flows a vector-field texture follows, over the unit square: the presets (`AnalyticField`) and
vectors sampled on a grid (`GridField`, made from a grid mesh's vertices by `grid_field_from_points`). Each has
``at(points (N, 2)) -> velocities (N, 2)`` float64."""

from dataclasses import dataclass

import numpy as np

from ..common.errors import InvalidInputError

PRESETS = ("ABC", "VORTEX")


@dataclass(frozen=True)
class AnalyticField:
    """A preset: ``ABC``, the Arnold-Beltrami-Childress flow (A, B, C = √3, √2, 1) on the slice z = ``slice_z``
    of its 2π-periodic cube, mapped onto the unit square; ``VORTEX``, a smooth vortex round the centre.
    ``speed`` scales the velocity."""

    kind: str = "ABC"
    slice_z: float = 0.0
    speed: float = 1.0

    def __post_init__(self):
        if self.kind not in PRESETS:
            raise InvalidInputError(f"The field must be one of {', '.join(PRESETS)}; got {self.kind!r}")

    def at(self, p):
        """Velocities (N, 2) float64 at domain points (N, 2)."""
        p = np.asarray(p, np.float64)
        x, y = p[:, 0], p[:, 1]
        if self.kind == "ABC":
            a, b, c = np.sqrt(3.0), np.sqrt(2.0), 1.0
            two_pi = 2.0 * np.pi
            u = a * np.sin(self.slice_z) + c * np.cos(two_pi * y)
            v = b * np.sin(two_pi * x) + a * np.cos(self.slice_z)
            return self.speed * np.stack([u, v], 1) / two_pi
        dx, dy = x - 0.5, y - 0.5
        w = 0.05 / (dx * dx + dy * dy + 0.01)
        return self.speed * np.stack([-dy * w, dx * w], 1)


@dataclass(frozen=True)
class GridField:
    """Vectors sampled on a regular grid: values (H, W, 2) float (row 0 at the bottom), vertex (i, j) at domain
    point (i / (W - 1), j / (H - 1)); bilinear in between, clamped at the border."""

    values: np.ndarray

    def __post_init__(self):
        v = np.asarray(self.values)
        if v.ndim != 3 or v.shape[2] != 2 or min(v.shape[:2]) < 2:
            raise InvalidInputError(f"A grid field needs at least 2 x 2 vectors of 2 components; got {v.shape}")
        if not np.all(np.isfinite(v)):
            raise InvalidInputError("The grid field has NaN or infinite vectors")

    def at(self, p):
        v = np.asarray(self.values, np.float64)
        h, w = v.shape[:2]
        p = np.asarray(p, np.float64)
        x = np.clip(p[:, 0], 0.0, 1.0) * (w - 1)
        y = np.clip(p[:, 1], 0.0, 1.0) * (h - 1)
        i0 = np.minimum(np.floor(x).astype(np.int64), w - 2)
        j0 = np.minimum(np.floor(y).astype(np.int64), h - 2)
        fx, fy = (x - i0)[:, None], (y - j0)[:, None]
        return ((v[j0, i0] * (1 - fx) + v[j0, i0 + 1] * fx) * (1 - fy)
                + (v[j0 + 1, i0] * (1 - fx) + v[j0 + 1, i0 + 1] * fx) * fy)


def grid_field_from_points(positions, vectors):
    """A `GridField` from a regular grid's vertices (any order): positions (V, 3) on an nx x ny lattice in their
    xy plane, vectors (V, 3) (their x and y are used), velocities made relative to the grid's size so the domain
    is the unit square. Raises `InvalidInputError` when the vertices are not such a lattice."""
    p = np.asarray(positions, np.float64)
    v = np.asarray(vectors, np.float64)
    if len(p) < 4 or p.shape != v.shape:
        raise InvalidInputError("A vector field needs a grid of at least 2 x 2 vertices, each with a vector")
    lo, hi = p[:, :2].min(axis=0), p[:, :2].max(axis=0)
    size = hi - lo
    if not np.all(size > 0):
        raise InvalidInputError("The field's grid is flat in x or y: it must span an area in its xy plane")
    rel = (p[:, :2] - lo) / size
    keys = [np.unique(np.round(rel[:, a] * 1e6)) for a in (0, 1)]
    nx, ny = len(keys[0]), len(keys[1])
    if nx * ny != len(p) or nx < 2 or ny < 2:
        raise InvalidInputError(f"The field's mesh is not a regular grid: {len(p)} vertices on {nx} x {ny} distinct "
                                "x and y values (use Add > Mesh > Grid, or a grid made from one)")
    i = np.searchsorted(keys[0], np.round(rel[:, 0] * 1e6))
    j = np.searchsorted(keys[1], np.round(rel[:, 1] * 1e6))
    values = np.zeros((ny, nx, 2))
    seen = np.zeros((ny, nx), bool)
    values[j, i] = v[:, :2] / size
    seen[j, i] = True
    if not seen.all():
        raise InvalidInputError("The field's mesh is not a regular grid: some lattice points have no vertex")
    return GridField(values)

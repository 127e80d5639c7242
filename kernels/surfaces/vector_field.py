"""Vector-field textures by line integral convolution with explicit Euler advection ([Nellmedin 2014, §5.5.4], [Cabral
1993]).

A steady 2-D field over the unit square (an analytic preset, or vectors sampled on a W x H grid) is drawn by
advecting seed points laid on a regular lattice: every point carries a noise value, moves by explicit Euler
(x ← x + h f(x), eq. 5.1) for a number of steps, and splats its value into the pixel it is in after each step; the
image is the mean of the values splatted into each pixel, so streaks follow the streamlines. The seed lattice (one
jittered seed per cell) is denser when the camera is nearer ([Nellmedin 2014]'s distance metric per point, a linear map
between Near and Far).

`advect` and `splat` are the numpy reference of the GPU path (`gpu_shaders.surfaces.lic`: a compute shader steps
the points, ping-pong, and additive point drawing accumulates), and `lic_image` puts them together.
Coordinates: domain (0, 0) .. (1, 1); pixel (i, j) covers [i / W, (i + 1) / W) x [j / H, (j + 1) / H), row 0 at the
bottom.
"""

from dataclasses import dataclass

import numpy as np

from ..common.errors import InvalidInputError

PRESETS = ("ABC", "VORTEX")
#: Largest seed lattice side (points per side), a guard against a camera right on the surface.
MAX_SEEDS_PER_SIDE = 4096


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


def seeds_per_side(base, distance, near, far, max_factor=4.0):
    """Seed lattice points per side: ``base`` times a factor that is ``max_factor`` at ``near`` or closer, 1 at
    ``far`` or beyond, linear between ([Nellmedin 2014]'s linear distance map), at most `MAX_SEEDS_PER_SIDE`."""
    if not (0 <= near < far) or not np.isfinite(distance):
        raise InvalidInputError(f"Near and Far must satisfy 0 <= near < far; got {near!r}, {far!r}")
    t = np.clip((far - distance) / (far - near), 0.0, 1.0)
    return int(min(MAX_SEEDS_PER_SIDE, max(1, round(base * (1.0 + (max_factor - 1.0) * t)))))


def seed_points(per_side, seed=0):
    """A per_side² lattice of cells with one seed in each, jittered inside its cell (a bare lattice lines up with
    the pixels and bands), and a noise value each: points (N, 2) float32, values (N,) float32 in [0, 1) (white
    noise). Both from ``seed``."""
    if per_side < 1:
        raise InvalidInputError("Seeds: at least one streak per side is needed")
    rng = np.random.default_rng(seed)
    i, j = np.meshgrid(np.arange(per_side), np.arange(per_side))
    cells = np.stack([i.ravel(), j.ravel()], 1)
    points = ((cells + rng.random(cells.shape)) / per_side).astype(np.float32)
    return points, rng.random(len(points)).astype(np.float32)


def advect(points, field, step, steps):
    """Explicit Euler (eq. 5.1) in float32, as the GPU steps: x_{k+1} = x_k + h f(x_k).
    points (N, 2) -> trajectory (steps + 1, N, 2) float32 (row 0 the seeds)."""
    if not (np.isfinite(step) and step > 0) or int(steps) != steps or steps < 0:
        raise InvalidInputError(f"The step must be positive and the step count a whole number; got {step!r}, "
                                f"{steps!r}")
    out = np.empty((int(steps) + 1, len(points), 2), np.float32)
    out[0] = points
    h = np.float32(step)
    for k in range(int(steps)):
        out[k + 1] = out[k] + h * field.at(out[k]).astype(np.float32)
    return out


def splat(trajectory, values, width, height):
    """Sum of the values splatted into each pixel along the trajectory, and how many: (H, W) float64 each.
    Points outside the unit square splat nothing."""
    p = np.asarray(trajectory, np.float64).reshape(-1, 2)
    v = np.broadcast_to(np.asarray(values, np.float64), trajectory.shape[:2]).ravel()
    i, j = np.floor(p[:, 0] * width), np.floor(p[:, 1] * height)
    inside = (i >= 0) & (i < width) & (j >= 0) & (j < height)
    idx = (j[inside] * width + i[inside]).astype(np.int64)
    total = np.bincount(idx, weights=v[inside], minlength=width * height).reshape(height, width)
    count = np.bincount(idx, minlength=width * height).reshape(height, width).astype(np.float64)
    return total, count


def lic_image(field, width, height, per_side, step, steps, seed=0):
    """The field's texture: (H, W) float32 in [0, 1], each pixel the mean noise value splatted into it (0.5
    where nothing passed)."""
    points, values = seed_points(per_side, seed)
    total, count = splat(advect(points, field, step, steps), values, width, height)
    return np.where(count > 0, total / np.maximum(count, 1), 0.5).astype(np.float32)


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

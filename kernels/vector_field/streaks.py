"""Vector-field textures by line integral convolution with explicit Euler advection ([Nellmedin 2014, §5.5.4], [Cabral
1993]).

A steady 2-D field over the unit square (an analytic preset, or vectors sampled on a W x H grid) is drawn by
advecting seed points laid on a regular lattice: every point carries a noise value, moves by explicit Euler
(x ← x + h f(x), eq. 5.1) for a number of steps, and splats its value into the pixel it is in after each step; the
image is the mean of the values splatted into each pixel, so streaks follow the streamlines. The seed lattice (one
jittered seed per cell) is denser when the camera is nearer ([Nellmedin 2014]'s distance metric per point, a linear map
between Near and Far).

`advect` and `splat` are the numpy reference of the GPU path (`gpu_shaders.vector_field.streaks`: a compute shader steps
the points, ping-pong, and additive point drawing accumulates), and `streak_image` puts them together.
Coordinates: domain (0, 0) .. (1, 1); pixel (i, j) covers [i / W, (i + 1) / W) x [j / H, (j + 1) / H), row 0 at the
bottom.
"""

import numpy as np

from ..common.errors import InvalidInputError

#: Largest seed lattice side (points per side), a guard against a camera right on the surface.
MAX_SEEDS_PER_SIDE = 4096


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


def streak_image(field, width, height, per_side, step, steps, seed=0):
    """The field's texture: (H, W) float32 in [0, 1], each pixel the mean noise value splatted into it (0.5
    where nothing passed)."""
    points, values = seed_points(per_side, seed)
    total, count = splat(advect(points, field, step, steps), values, width, height)
    return np.where(count > 0, total / np.maximum(count, 1), 0.5).astype(np.float32)

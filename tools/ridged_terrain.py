"""A synthetic terrain for the tests, benches and demo (not shipped): ridged multi-octave value noise with a plain
and a plateau.

Deterministic for a seed; vectorised (one bilinear upsample of a random lattice per octave).
"""

import numpy as np


def _octave(rng, size, cells):
    lattice = rng.random((cells + 2, cells + 2))
    t = np.linspace(0, cells, size, endpoint=False)
    i = t.astype(np.int64)
    f = t - i
    f = f * f * (3 - 2 * f)  # smoothstep: no creases at lattice lines
    rows = lattice[i] * (1 - f)[:, None] + lattice[i + 1] * f[:, None]
    return rows[:, i] * (1 - f)[None, :] + rows[:, i + 1] * f[None, :]


def ridged_terrain(size=1025, seed=0, octaves=8):
    """(size, size) float32 heights in [0, 1]: ridged mountains, a flat plain on the west, a plateau."""
    rng = np.random.default_rng(seed)
    h = np.zeros((size, size))
    amp, cells, total = 1.0, 3, 0.0
    for _ in range(octaves):
        n = _octave(rng, size, cells)
        h += amp * (1.0 - np.abs(2.0 * n - 1.0)) ** 2  # ridges
        total += amp
        amp *= 0.5
        cells *= 2
    h /= total
    y, x = np.mgrid[0:size, 0:size] / (size - 1)
    plain = np.clip((x - 0.18) / 0.12, 0, 1)
    h = h * plain ** 2 + 0.05 * (1 - plain ** 2)
    plateau = np.hypot(x - 0.7, y - 0.35) < 0.09
    h[plateau] = np.maximum(h[plateau], 0.7)
    return ((h - h.min()) / (h.max() - h.min())).astype(np.float32)

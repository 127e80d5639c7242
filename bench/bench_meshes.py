"""Meshes for benchmarks."""

import numpy as np


def grid(n):
    """Square grid: (n + 1)^2 vertices (float32), 2 n^2 triangles (int32)."""
    xs, ys = np.meshgrid(np.arange(n + 1, dtype=np.float32), np.arange(n + 1, dtype=np.float32))
    pos = np.stack([xs.ravel(), ys.ravel(), np.zeros(xs.size, np.float32)], 1)
    i = (np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]).ravel()
    tris = np.concatenate([np.stack([i, i + 1, i + n + 2], 1), np.stack([i, i + n + 2, i + n + 1], 1)])
    return pos, tris.astype(np.int32)

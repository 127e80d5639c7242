"""Small test meshes built with numpy (no Blender): closed, open, with seams."""

import numpy as np


def octahedron():
    """Closed manifold, 6 vertices, 8 counter-clockwise triangles."""
    v = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], np.float32)
    f = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]], np.int32)
    return v, f


def torus(major=24, minor=12, r_major=1.0, r_minor=0.35):
    """Closed manifold torus: (major * minor) vertices, 2 * major * minor triangles."""
    u = np.linspace(0, 2 * np.pi, major, endpoint=False)[:, None]
    w = np.linspace(0, 2 * np.pi, minor, endpoint=False)[None, :]
    x = (r_major + r_minor * np.cos(w)) * np.cos(u)
    y = (r_major + r_minor * np.cos(w)) * np.sin(u)
    z = np.broadcast_to(r_minor * np.sin(w), x.shape)
    v = np.stack([x, y, z], -1).reshape(-1, 3).astype(np.float32)
    i, j = np.meshgrid(np.arange(major), np.arange(minor), indexing="ij")
    a = i * minor + j
    b = ((i + 1) % major) * minor + j
    c = ((i + 1) % major) * minor + (j + 1) % minor
    d = i * minor + (j + 1) % minor
    f = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return v, f.astype(np.int32)


def random_closed(seed, major=None, minor=None):
    """A randomly jittered torus with randomly permuted vertex ids (so edge directions are mixed)."""
    rng = np.random.default_rng(seed)
    v, f = torus(major or int(rng.integers(3, 9)), minor or int(rng.integers(3, 7)))
    v = v + rng.normal(scale=0.02, size=v.shape).astype(np.float32)
    perm = rng.permutation(len(v))
    inverse = np.argsort(perm)
    return v[perm], inverse[f].astype(np.int32)


def grid(n=4):
    """Open square grid in the z = 0 plane: (n + 1)^2 vertices, 2 n^2 triangles."""
    xs, ys = np.meshgrid(np.arange(n + 1, dtype=np.float32), np.arange(n + 1, dtype=np.float32))
    v = np.stack([xs.ravel(), ys.ravel(), np.zeros(xs.size, np.float32)], 1)
    i = (np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]).ravel()
    f = np.concatenate([np.stack([i, i + 1, i + n + 2], 1), np.stack([i, i + n + 2, i + n + 1], 1)])
    return v, f.astype(np.int32)


def edge_use_counts(triangles):
    """Undirected edge -> number of triangles using it, as (edges (E, 2), counts (E,))."""
    t = np.asarray(triangles, np.int64)
    e = np.sort(np.stack([t, np.roll(t, -1, axis=1)], -1).reshape(-1, 2), axis=1)
    return np.unique(e, axis=0, return_counts=True)


def is_closed_oriented_manifold(triangles):
    """Every undirected edge used exactly twice, each directed edge once (consistent orientation)."""
    t = np.asarray(triangles, np.int64)
    _, counts = edge_use_counts(t)
    directed = np.stack([t, np.roll(t, -1, axis=1)], -1).reshape(-1, 2)
    return bool(np.all(counts == 2)) and len(np.unique(directed, axis=0)) == len(directed)

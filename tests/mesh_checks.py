"""Checks on triangle meshes shared by the tests (no Blender)."""

import numpy as np


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

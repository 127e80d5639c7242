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


def assert_parts_weld_into(parts, whole):
    """Meshes ``parts`` (each with positions (n, 3) and triangles (m, 3)), welded where positions coincide bit for bit,
    are ``whole``: the same vertices and the same triangles (as triples of positions, winding kept), every triangle
    made by exactly one part."""
    from tessera.kernels.common.weld import weld_triangles

    assert sum(len(p.triangles) for p in parts) == len(whole.triangles)
    offsets = np.cumsum([0] + [len(p.positions) for p in parts])
    pos, tris, _, kept = weld_triangles(np.concatenate([p.positions for p in parts]),
                                        np.concatenate([p.triangles + o for p, o in zip(parts, offsets[:-1],
                                                                                        strict=True)]))
    assert len(kept) == len(whole.triangles) and len(pos) == len(whole.positions)
    assert np.array_equal(np.unique(pos, axis=0), np.unique(whole.positions, axis=0))

    def triangles(p, t):
        keys = [tuple(map(tuple, tri)) for tri in p[t]]  # each rotated to start at its smallest corner
        return {min(k[i:] + k[:i] for i in range(3)) for k in keys}

    assert triangles(pos, tris) == triangles(whole.positions, whole.triangles)

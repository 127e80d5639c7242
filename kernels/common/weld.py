"""Welding by exact position: vertices whose float32 coordinates are bit-identical (``-0.0`` and ``0.0`` counted equal)
become one vertex. Joins meshes made in pieces that share their seam points exactly, such as the blocks of a terrain
meshed by separate render-farm tasks, into the mesh one process would make."""

import numpy as np


def weld_exact(positions):
    """Merge coincident vertices.

    positions: (n, 3) float32. Returns ``(keep, index)``: keep (k,) int64, the first vertex of each distinct position
    in order of first appearance; index (n,) int64, each vertex's welded index (into ``positions[keep]``).
    """
    p = np.ascontiguousarray(np.asarray(positions, np.float32).reshape(-1, 3) + np.float32(0.0))  # -0.0 -> 0.0
    key = p.view(np.dtype((np.void, 12))).ravel()
    _, first, inverse = np.unique(key, return_index=True, return_inverse=True)
    order = np.argsort(first, kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return first[order].astype(np.int64), rank[inverse.ravel()].astype(np.int64)


def weld_triangles(positions, triangles):
    """Weld ``positions`` (n, 3) float32 and re-index ``triangles`` (m, 3) int; triangles left with a repeated corner
    are dropped. Returns ``(positions (k, 3) float32, triangles (m', 3) int32, keep (k,) int64, kept (m',) int64)``,
    ``kept`` the surviving triangles' indices."""
    keep, index = weld_exact(positions)
    tris = index[np.asarray(triangles, np.int64)]
    ok = (tris[:, 0] != tris[:, 1]) & (tris[:, 1] != tris[:, 2]) & (tris[:, 0] != tris[:, 2])
    kept = np.nonzero(ok)[0]
    return np.asarray(positions, np.float32)[keep], tris[kept].astype(np.int32), keep, kept

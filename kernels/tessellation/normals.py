"""Vertex normals for the curved patches, and the hard-edge policy.

PN triangles and Phong tessellation move a point using the normals of its triangle's corners. Where a
vertex has several normals (sharp edges, custom split normals) the two triangles of an edge would build
different edge curves and the surface would crack. Two policies (`NORMAL_MODES`):

``WATERTIGHT`` (default)
    The geometry uses one shared normal per vertex: the angle-weighted mean of its corner normals.
    Shading keeps the split normals, so a closed input gives a closed output that still shades sharp.
``SPLIT``
    Each distinct corner normal gets its own vertex (`split_by_normals`), so the geometry follows the
    split normals and opens along the sharp edges; the caller reports how many edges opened.
"""

import numpy as np

from ..common.tolerances import SAME_NORMAL_DOT

NORMAL_MODES = ("WATERTIGHT", "SPLIT")


def _unit(v):
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.divide(v, length, out=np.zeros_like(v), where=length > 0)


def corner_angles(positions, triangles):
    """Interior angle of every face corner: (V, 3), (T, 3) -> (T, 3) float64 in [0, pi] (0 if degenerate)."""
    p = np.asarray(positions, np.float64)[triangles]
    e_next = _unit(np.roll(p, -1, axis=1) - p)
    e_prev = _unit(np.roll(p, 1, axis=1) - p)
    cos = np.clip(np.einsum("tci,tci->tc", e_next, e_prev), -1.0, 1.0)
    return np.arccos(cos)


def face_unit_normals(positions, triangles):
    """(V, 3), (T, 3) -> (T, 3) float64 unit normals (zero for degenerate faces)."""
    p = np.asarray(positions, np.float64)[triangles]
    return _unit(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]))


def _accumulate(triangles, values, n_vertices):
    """Sum (T, 3, 3) per-corner vectors onto vertices -> (V, 3) float64."""
    idx = triangles.ravel()
    flat = values.reshape(-1, 3)
    return np.stack([np.bincount(idx, weights=flat[:, c], minlength=n_vertices) for c in range(3)], axis=1)


def shared_vertex_normals(positions, triangles, corner_normals=None):
    """One unit normal per vertex: the corner-angle-weighted mean of its corner normals.

    positions: (V, 3); triangles: (T, 3) int; corner_normals: (T, 3, 3) or None (then the face normals,
    i.e. smooth shading). A vertex whose normals cancel falls back to its angle-weighted face normals,
    then to +Z. Returns (V, 3) float64, unit length.
    """
    n_vertices = len(positions)
    angles = corner_angles(positions, triangles)[..., None]
    faces = face_unit_normals(positions, triangles)[:, None, :]
    source = faces if corner_normals is None else np.asarray(corner_normals, np.float64)
    normals = _unit(_accumulate(triangles, angles * source, n_vertices))
    missing = ~normals.any(axis=1)
    if missing.any():
        fallback = _unit(_accumulate(triangles, angles * np.broadcast_to(faces, source.shape), n_vertices))
        normals[missing] = fallback[missing]
        still = ~normals.any(axis=1)
        normals[still] = (0.0, 0.0, 1.0)
    return normals


def split_corners(triangles, corner_normals, vertex_normals):
    """Which corners carry a normal different from their vertex's shared normal: -> (T, 3) bool."""
    cn = _unit(np.asarray(corner_normals, np.float64))
    dots = np.einsum("tci,tci->tc", cn, vertex_normals[triangles])
    return dots < SAME_NORMAL_DOT


def split_by_normals(triangles, corner_normals, n_vertices):
    """Give every distinct (vertex, corner normal) pair its own vertex.

    triangles: (T, 3) int; corner_normals: (T, 3, 3). Normals within `SAME_NORMAL_DOT` of each other
    are treated as equal (they are quantised before comparison). Returns ``(triangles (T, 3) int32,
    source_vertex (V', ) int64, vertex_normals (V', 3) float64)``; output vertex ``i`` copies input vertex
    ``source_vertex[i]``. Vertices with a single normal keep their relative order.
    """
    cn = _unit(np.asarray(corner_normals, np.float64)).reshape(-1, 3)
    quant = np.round(cn * 1e5).astype(np.int64)
    keys = np.concatenate([triangles.reshape(-1, 1).astype(np.int64), quant], axis=1)
    uniq, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    source = uniq[:, 0]
    normals = cn[first]
    return inverse.reshape(triangles.shape).astype(np.int32), source, normals

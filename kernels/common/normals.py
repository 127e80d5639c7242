"""Normals of triangle meshes every capability uses: unit face normals, corner angles, per-vertex sums of corner
values, and the angle-weighted shared vertex normal."""

import numpy as np


def unit(v):
    """Rows of ``v`` (..., 3) scaled to unit length (zero rows stay zero)."""
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.divide(v, length, out=np.zeros_like(v), where=length > 0)


def corner_angles(positions, triangles):
    """Interior angle of every face corner: (V, 3), (T, 3) -> (T, 3) float64 in [0, pi] (0 if degenerate)."""
    p = np.asarray(positions, np.float64)[triangles]
    e_next = unit(np.roll(p, -1, axis=1) - p)
    e_prev = unit(np.roll(p, 1, axis=1) - p)
    cos = np.clip(np.einsum("tci,tci->tc", e_next, e_prev), -1.0, 1.0)
    return np.arccos(cos)


def face_unit_normals(positions, triangles):
    """(V, 3), (T, 3) -> (T, 3) float64 unit normals (zero for degenerate faces)."""
    p = np.asarray(positions, np.float64)[triangles]
    return unit(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]))


def accumulate(triangles, values, n_vertices):
    """Sum per-corner values (T, 3, C) onto their vertices, in corner order -> (V, C) float64."""
    idx = np.asarray(triangles).ravel()
    flat = np.asarray(values, np.float64).reshape(len(idx), -1)
    return np.stack([np.bincount(idx, weights=flat[:, c], minlength=n_vertices) for c in range(flat.shape[1])],
                    axis=1)


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
    normals = unit(accumulate(triangles, angles * source, n_vertices))
    missing = ~normals.any(axis=1)
    if missing.any():
        fallback = unit(accumulate(triangles, angles * np.broadcast_to(faces, source.shape), n_vertices))
        normals[missing] = fallback[missing]
        still = ~normals.any(axis=1)
        normals[still] = (0.0, 0.0, 1.0)
    return normals

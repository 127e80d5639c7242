"""Tangent-space displacement, the numpy reference of the geometry-nodes group and the preview shader.

A tangent-space vector map stores (x, y, z) per texel in the frame of the surface at that texel: x along the
UV map's U tangent, y along the bitangent, z along the normal (the convention of MikkTSpace-baked maps).
Per vertex: T is the tangent made orthogonal to the vertex normal N, B = sign x (N x T) with the sign of the
UV map's orientation, and the offset is strength x ((r - mid) T + (g - mid) B + (b - mid) N).
"""

import numpy as np

from ..common.errors import InvalidInputError
from ..common.tolerances import NO_DIRECTION


def sample_linear(image, uv):
    """Bilinear lookup with clamped edges, as Blender's image texture node (Linear, Extend) samples.

    image: (H, W, C) with row 0 at v = 0; uv: (..., 2). Texel (i, j) has its centre at ((j + 0.5) / W,
    (i + 0.5) / H). Returns (..., C) float64.
    """
    image = np.asarray(image)
    if image.ndim != 3:
        raise InvalidInputError(f"image must be (H, W, C), got shape {image.shape}")
    h, w = image.shape[:2]
    uv = np.asarray(uv, np.float64)
    x = uv[..., 0] * w - 0.5
    y = uv[..., 1] * h - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    xa, xb = np.clip(x0, 0, w - 1).astype(np.int64), np.clip(x0 + 1, 0, w - 1).astype(np.int64)
    ya, yb = np.clip(y0, 0, h - 1).astype(np.int64), np.clip(y0 + 1, 0, h - 1).astype(np.int64)
    img = image.astype(np.float64)
    top = img[ya, xa] * (1 - fx) + img[ya, xb] * fx
    bottom = img[yb, xa] * (1 - fx) + img[yb, xb] * fx
    return top * (1 - fy) + bottom * fy


def uv_orientation(corner_uvs, face_starts):
    """+1 for faces whose UVs turn counter-clockwise (the face's winding kept), -1 where mirrored.

    corner_uvs: (L, 2) in corner order; face_starts: (F,) first corner of each face (faces are consecutive).
    Degenerate faces count as +1. Returns (F,) float64.
    """
    uv = np.asarray(corner_uvs, np.float64)
    starts = np.asarray(face_starts, np.int64)
    ends = np.append(starts[1:], len(uv))
    face = np.repeat(np.arange(len(starts)), ends - starts)
    nxt = np.arange(len(uv)) + 1
    nxt[ends - 1] = starts
    area = np.bincount(face, uv[:, 0] * uv[nxt, 1] - uv[nxt, 0] * uv[:, 1], minlength=len(starts))
    return np.where(area < 0, -1.0, 1.0)


def tangent_frames(normals, tangents, signs):
    """Orthonormal (T, B) from unit normals (N, 3), tangents (N, 3) and bitangent signs (N,).

    T is ``tangents`` minus its normal part, normalised; B = signs x (N x T). Returns two (N, 3) float64.
    """
    n = np.asarray(normals, np.float64)
    t = np.asarray(tangents, np.float64)
    t = t - n * np.sum(n * t, axis=1, keepdims=True)
    length = np.linalg.norm(t, axis=1, keepdims=True)
    if np.any(length < NO_DIRECTION):
        raise InvalidInputError("a tangent is parallel to its normal (degenerate UVs)")
    t = t / length
    return t, np.asarray(signs, np.float64)[:, None] * np.cross(n, t)


def tangent_offsets(values, normals, tangents, signs, mid_level=0.0, strength=1.0):
    """Offsets (N, 3) float64 of a tangent-space vector map: values (N, 3) sampled map, the frame as in
    `tangent_frames`."""
    t, b = tangent_frames(normals, tangents, signs)
    d = (np.asarray(values, np.float64)[:, :3] - mid_level) * strength
    return d[:, :1] * t + d[:, 1:2] * b + d[:, 2:3] * np.asarray(normals, np.float64)


def triangle_tangents(corners, uvs):
    """Per-triangle tangents from UV derivatives (the classic construction, not MikkTSpace's smoothing):
    corners (T, 3, 3) positions, uvs (T, 3, 2). Returns (T, 3, 4) float32, the triangle's tangent (xyz, unit;
    zero for degenerate UVs) and bitangent sign (w) repeated on its three corners."""
    p = np.asarray(corners, np.float64)
    uv = np.asarray(uvs, np.float64)
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    d1, d2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    t = e1 * d2[:, 1:2] - e2 * d1[:, 1:2]
    length = np.linalg.norm(t, axis=1, keepdims=True)
    t = np.divide(t, length, out=np.zeros_like(t), where=length > 0)
    t *= np.where(det < 0, -1.0, 1.0)[:, None]
    out = np.empty((len(p), 3, 4), np.float32)
    out[..., :3] = t[:, None]
    out[..., 3] = np.where(det < 0, -1.0, 1.0)[:, None]
    return out

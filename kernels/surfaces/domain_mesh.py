"""The quad domain of a one-point surface and the meshes made from it ([Nunes 2011, §2.3–2.4]).

A patch of factor F is the unit square split into F x F quads (integer partitioning: the hardware
tessellator's count, (F + 1)² domain vertices and 2F² triangles; 8192 at F = 64, where `fractional_odd` would
clamp to 63 and give 7938, [Nunes 2011, correction 4]). `domain_pattern` is that pattern, the same for every surface and
every instance: the GPU path draws it once per control point and evaluates the formula per vertex.

`surface_mesh` bakes one surface into a welded triangle mesh: the domain's vertices are identified by the
surface's `parametric.Closure` (periodic and twisted edges, collapsing poles and apexes; for Steiner's surface
also the middle row, see `Steiner`), never by comparing positions, so self-intersecting surfaces keep their
sheets apart. Triangles that a collapse makes degenerate are dropped; corner UVs are the domain coordinates, so
the UV map has its seams where the surface closes.

`instance_positions` is the other path of [Nunes 2011]'s experiment: every instance's vertices computed on the CPU
and uploaded as one buffer; `upload_bytes` the memory accounting of Table 2.2.
"""

import functools
from dataclasses import dataclass

import numpy as np

from ..common.errors import InvalidInputError
from .parametric import PERIODIC, TWISTED

#: Highest factor, as the hardware tessellator's.
MAX_FACTOR = 64
#: Bytes of one vertex in [Nunes 2011]'s accounting (a float3 position).
VERTEX_BYTES = 12


@dataclass
class DomainMesh:
    """A baked surface. positions: (V, 3) float32; triangles: (T, 3) int32 (counter-clockwise seen from outside on
    closed orientable surfaces); uvs: (T, 3, 2) float32 corner domain coordinates; source: (V,) int64 the domain
    vertex (row-major over (u, v), u major) each vertex was evaluated at."""

    positions: np.ndarray
    triangles: np.ndarray
    uvs: np.ndarray
    source: np.ndarray


def check_factor(factor):
    if int(factor) != factor or not 1 <= factor <= MAX_FACTOR:
        raise InvalidInputError(f"The tessellation factor must be a whole number from 1 to {MAX_FACTOR}; got "
                                f"{factor!r}")
    return int(factor)


def pattern_counts(factor):
    """(domain vertices, triangles) of a factor-F patch: ((F + 1)², 2F²)."""
    f = check_factor(factor)
    return (f + 1) ** 2, 2 * f * f


def domain_pattern(factor):
    """The factor-F quad-domain pattern: uv (n, 2) float32 domain coordinates (vertex i * (F + 1) + j at
    (i / F, j / F)) and triangles (2F², 3) int32, each quad split along its (i, j)-(i+1, j+1) diagonal,
    counter-clockwise in (u, v)."""
    f = check_factor(factor)
    i, j = np.meshgrid(np.arange(f + 1), np.arange(f + 1), indexing="ij")
    uv = (np.stack([i.ravel(), j.ravel()], 1) / f).astype(np.float32)
    a = (np.arange(f)[:, None] * (f + 1) + np.arange(f)[None, :]).ravel()
    b, c, d = a + (f + 1), a + (f + 1) + 1, a + 1
    tris = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)]).astype(np.int32)
    return uv, tris


def _identified_pairs(f, closure, middle_row):
    """Pairs of domain vertex ids that are one point of the surface: (k, 2) int64."""
    n = f + 1
    k = np.arange(n)
    vid = lambda i, j: np.asarray(i) * n + np.asarray(j)  # noqa: E731
    pairs = []
    if closure.u == PERIODIC:
        pairs.append((vid(f, k), vid(0, k)))
    elif closure.u == TWISTED:
        pairs.append((vid(f, k), vid(0, f - k)))
    if closure.v == PERIODIC:
        pairs.append((vid(k, f), vid(k, 0)))
    elif closure.v == TWISTED:
        pairs.append((vid(k, f), vid(f - k, 0)))
    edges = {"u0": (0, k), "u1": (f, k), "v0": (k, 0), "v1": (k, f)}
    for name in closure.collapse:
        i, j = edges[name]
        ids = vid(i, j)
        pairs.append((ids, np.full_like(ids, ids[0])))
    if middle_row and f % 2 == 0:
        ids = vid(k, f // 2)
        pairs.append((ids, np.full_like(ids, ids[0])))
    if not pairs:
        return np.zeros((0, 2), np.int64)
    return np.concatenate([np.stack(p, 1) for p in pairs]).astype(np.int64)


def weld_ids(factor, closure, middle_row=False):
    """For each domain vertex the welded vertex it becomes: (F + 1)² int64, numbered in domain order of each
    vertex's first domain occurrence."""
    f = check_factor(factor)
    labels = np.arange((f + 1) ** 2, dtype=np.int64)
    pairs = _identified_pairs(f, closure, middle_row)
    while len(pairs):  # connected components: every id takes the smallest id it is identified with
        lo = np.minimum(labels[pairs[:, 0]], labels[pairs[:, 1]])
        before = labels.copy()
        np.minimum.at(labels, pairs[:, 0], lo)
        np.minimum.at(labels, pairs[:, 1], lo)
        labels = labels[labels]
        if np.array_equal(labels, before):
            break
    _, inverse = np.unique(labels, return_inverse=True)
    return inverse.reshape(-1)


def surface_mesh(surface, factor):
    """Bake ``surface`` (a `parametric` surface) at factor F into a welded `DomainMesh`."""
    uv, tris = domain_pattern(factor)
    closure = surface.closure
    ids = weld_ids(factor, closure, getattr(surface, "middle_row", False))
    n_out = int(ids.max()) + 1
    source = np.full(n_out, len(ids), np.int64)
    np.minimum.at(source, ids, np.arange(len(ids)))
    positions = surface.point(uv[source, 0].astype(np.float64), uv[source, 1].astype(np.float64))
    if not np.all(np.isfinite(positions)):
        raise InvalidInputError("The surface's parameters give points that are not finite numbers")
    welded = ids[tris]
    keep = (welded[:, 0] != welded[:, 1]) & (welded[:, 1] != welded[:, 2]) & (welded[:, 0] != welded[:, 2])
    corner_uv = uv[tris[keep]]
    welded = welded[keep]
    if not len(welded):
        raise InvalidInputError(f"At Factor {factor} every triangle of the surface folds onto its seams, leaving "
                                "nothing to mesh: use a Factor of 2 or more")
    if closure.flip:
        welded, corner_uv = welded[:, ::-1], corner_uv[:, ::-1]
    return DomainMesh(positions.astype(np.float32), np.ascontiguousarray(welded, np.int32),
                      np.ascontiguousarray(corner_uv, np.float32), source)


def instance_positions(surface, factor, control_points):
    """The CPU path of the experiment: every instance's domain vertices, offset by its control point, as one
    buffer. control_points: (N, 3) -> (N * (F + 1)², 3) float32 (instance-major, domain order)."""
    uv, _ = domain_pattern(factor)
    local = surface.point(uv[:, 0].astype(np.float64), uv[:, 1].astype(np.float64))
    cp = np.asarray(control_points, np.float64).reshape(-1, 3)
    return (cp[:, None, :] + local[None, :, :]).reshape(-1, 3).astype(np.float32)


def upload_bytes(instances, factor):
    """Table 2.2's accounting: (bytes of N patches as a non-indexed triangle buffer of float3 positions,
    bytes of N control points) = (N · 2F² · 3 · 12, N · 12)."""
    _, triangles = pattern_counts(factor)
    return instances * triangles * 3 * VERTEX_BYTES, instances * VERTEX_BYTES


@functools.lru_cache(maxsize=64)
def bounding_radius(surface, factor=32):
    """Largest distance of the surface from its control point (sampled on the factor-F domain, +1% margin).
    Cached per surface (surfaces are frozen, hashable dataclasses): a live preview asks every frame."""
    uv, _ = domain_pattern(factor)
    p = surface.point(uv[:, 0].astype(np.float64), uv[:, 1].astype(np.float64))
    return 1.01 * float(np.linalg.norm(p, axis=1).max())


def camera_factors(surface, control_points, camera, edge_pixels=8.0):
    """A factor per instance from the camera ([Nunes 2011]'s "level from the camera"): its bounding sphere's radius in
    pixels r_px, and ``ceil(2π r_px / edge_pixels)`` segments around, in [1, MAX_FACTOR]. camera: a
    `kernels.common.camera.Camera` in the control points' space; instances behind the eye get factor 1.
    Returns (N,) int64."""
    if not (np.isfinite(edge_pixels) and edge_pixels > 0):
        raise InvalidInputError(f"Edge pixels must be a positive number; got {edge_pixels!r}")
    cp = np.asarray(control_points, np.float64).reshape(-1, 3)
    view, proj = np.asarray(camera.view, np.float64), np.asarray(camera.projection, np.float64)
    focal = 0.5 * camera.height * proj[1, 1]
    radius = bounding_radius(surface)
    if camera.orthographic:
        r_px = np.full(len(cp), radius * focal)
    else:
        depth = -(cp @ view[2, :3] + view[2, 3])  # distance in front of the eye
        r_px = np.where(depth > 1e-12, radius * focal / np.maximum(depth, 1e-12), 0.0)
    return np.clip(np.ceil(2 * np.pi * r_px / edge_pixels), 1, MAX_FACTOR).astype(np.int64)

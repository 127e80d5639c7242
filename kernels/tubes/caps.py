"""End caps of open tubes: one n-gon (FLAT) or a hemisphere of rings closed by a triangle fan (ROUND).

Caps reuse the end ring of the body, so a capped open tube is a closed, manifold surface. Ring ``k`` of the
body has vertices ``ring_v + j`` and ring edges ``ring_e + j`` (side j to j+1); corner edges list the edge
from each corner to the next. New vertices and edges are numbered from ``v_next`` and ``e_next``.
"""

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class CapEnds:
    """The tube ends that get a cap, ``E`` of them: centre, t, n, b (E, 3) float64 the end point and its frame
    (unit tangent, normal, binormal); radius (E,) float64; ring_v, ring_e (E,) int64 the first vertex and first
    ring edge of the end ring in the body; material (E,) int32."""

    centre: np.ndarray
    t: np.ndarray
    n: np.ndarray
    b: np.ndarray
    radius: np.ndarray
    ring_v: np.ndarray
    ring_e: np.ndarray
    material: np.ndarray


@dataclass
class CapPiece:
    """Caps of one side of one run of tubes (`cap_pieces`).

    positions, normals: (V, 3) float32 new vertices; edges: (K, 2) int64 new edges; per block of faces of one
    width: faces and corner_edges (F, k) int64, materials (F,), uvs (F * k, 2) float32 when asked for, and
    corner_normals (F * k, 3) float32 (FLAT only).
    """

    positions: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.float32))
    normals: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.float32))
    edges: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64))
    faces: list = field(default_factory=list)
    corner_edges: list = field(default_factory=list)
    materials: list = field(default_factory=list)
    uvs: list = field(default_factory=list)
    corner_normals: list = field(default_factory=list)


def cap_sizes(kind, n):
    """(new vertices, new edges, faces, corners) of one cap with ``n`` sides."""
    if kind == "FLAT":
        return 0, 0, 1, n
    m = max(1, n // 4)
    return (m - 1) * n + 1, (2 * (m - 1) + 1) * n, m * n, (4 * (m - 1) + 3) * n


def cap_pieces(kind, n, side, ends, v_next, e_next, uvs):
    """Caps facing ``side`` * T (-1: curve starts, +1: curve ends) for the `CapEnds` ``ends`` with ``n`` sides;
    new vertices and edges are numbered from ``v_next`` and ``e_next``. Returns a `CapPiece`."""
    centre, t, nrm, bin_, radius = ends.centre, ends.t, ends.n, ends.b, ends.radius
    ring_v, ring_e, mat = ends.ring_v, ends.ring_e, ends.material
    j = np.arange(n)
    theta = 2 * np.pi * j / n
    out = CapPiece()
    count = len(centre)
    if kind == "FLAT":
        order = (-j) % n if side < 0 else j  # a start cap faces -T: reversed ring order
        out.faces.append(ring_v[:, None] + order)
        edge_side = (order - 1) % n if side < 0 else j
        out.corner_edges.append(ring_e[:, None] + edge_side)
        out.materials.append(mat)
        out.corner_normals.append(np.repeat(side * t, n, axis=0).astype(np.float32))
        if uvs:
            disk = _disk_uv(theta[order], 1.0)
            out.uvs.append(np.tile(disk, (count, 1)).astype(np.float32))
        return out

    m = max(1, n // 4)
    j1 = (j + 1) % n
    phi = (np.pi / 2) * np.arange(1, m) / m
    per_v, per_e = cap_sizes("ROUND", n)[:2]
    vb = v_next + np.arange(count)[:, None] * per_v
    eb = e_next + np.arange(count)[:, None] * per_e
    radial = (np.cos(theta)[None, None, :, None] * nrm[:, None, None, :]
              + np.sin(theta)[None, None, :, None] * bin_[:, None, None, :])  # (E, 1, n, 3)
    along = side * t[:, None, None, :]
    dirs = np.cos(phi)[None, :, None, None] * radial + np.sin(phi)[None, :, None, None] * along
    dirs = np.concatenate((dirs.reshape(count, -1, 3), along[:, 0]), axis=1)  # rings 1..m-1, then the pole
    out.positions = (centre[:, None, :] + radius[:, None, None] * dirs).reshape(-1, 3).astype(np.float32)
    out.normals = dirs.reshape(-1, 3).astype(np.float32)

    def vert(i, jj):
        return ring_v[:, None] + jj if i == 0 else vb + (i - 1) * n + jj

    def ring_edge(i, jj):
        return ring_e[:, None] + jj if i == 0 else eb + (i - 1) * n + jj

    def long_edge(i, jj):
        return eb + (m - 1) * n + (i - 1) * n + jj

    pole = vb + (m - 1) * n + 0 * j
    blocks = [np.stack((vert(i, j), vert(i, j1)), axis=-1) for i in range(1, m)]
    blocks += [np.stack((vert(i - 1, j), vert(i, j)), axis=-1) for i in range(1, m)]
    blocks.append(np.stack((vert(m - 1, j), pole), axis=-1))
    out.edges = np.concatenate(blocks, axis=1).reshape(-1, 2)
    for i in range(1, m):
        a, a1, b, b1 = vert(i - 1, j), vert(i - 1, j1), vert(i, j), vert(i, j1)
        ra, rb, lj, lj1 = ring_edge(i - 1, j), ring_edge(i, j), long_edge(i, j), long_edge(i, j1)
        f, ce = ((a, a1, b1, b), (ra, lj1, rb, lj)) if side > 0 else ((b, b1, a1, a), (rb, lj1, ra, lj))
        out.faces.append(np.stack(f, axis=-1).reshape(-1, 4))
        out.corner_edges.append(np.stack(ce, axis=-1).reshape(-1, 4))
        out.materials.append(np.repeat(mat, n))
        if uvs:
            sa, sb = np.cos((np.pi / 2) * (i - 1) / m), np.cos((np.pi / 2) * i / m)
            out.uvs.append(_corner_uvs(theta, (sa, sa, sb, sb) if side > 0 else (sb, sb, sa, sa), count))
    a, a1, ra = vert(m - 1, j), vert(m - 1, j1), ring_edge(m - 1, j)
    pe, pe1 = eb + 2 * (m - 1) * n + j, eb + 2 * (m - 1) * n + j1
    f, ce = ((a, a1, pole), (ra, pe1, pe)) if side > 0 else ((pole, a1, a), (pe1, ra, pe))
    out.faces.append(np.stack(f, axis=-1).reshape(-1, 3))
    out.corner_edges.append(np.stack(ce, axis=-1).reshape(-1, 3))
    out.materials.append(np.repeat(mat, n))
    if uvs:
        s = np.cos((np.pi / 2) * (m - 1) / m)
        out.uvs.append(_corner_uvs(theta, (s, s, 0.0) if side > 0 else (0.0, s, s), count))
    return out


def _disk_uv(theta, scale):
    return np.stack((0.5 + 0.5 * scale * np.cos(theta), 0.5 + 0.5 * scale * np.sin(theta)), axis=-1)


def _corner_uvs(theta, scales, count):
    """Planar disk UVs for faces whose corners sit at (θ_j or θ_j+1, latitude scale): (count * n * k, 2)."""
    th1 = theta + 2 * np.pi / len(theta)
    # corners follow the faces: (j, j+1, j+1, j) for quads; (j, j+1, pole) or (pole, j+1, j) for the fan, where the
    # pole's scale is 0 so its angle does not matter
    angles = (theta, th1, th1, theta) if len(scales) == 4 else (theta, th1, theta)
    uv = np.stack([_disk_uv(a, s) for a, s in zip(angles, scales, strict=True)], axis=1)
    return np.tile(uv.reshape(-1, 2), (count, 1)).astype(np.float32)

"""The edge structure of one Loop level, built once for the coarse mesh and then refined analytically.

Local edge ``k`` of a triangle runs from corner ``k`` to corner ``k + 1``. A level's vertices are the previous
level's vertices (same ids) followed by one vertex per edge (id ``V + e``). Triangle ``t = (a, b, c)`` with edge
vertices ``m0 = m_ab, m1 = m_bc, m2 = m_ca`` has four children, numbered ``4 t + slot`` in the seed's T/L/C/R
order (digest §A.2.3; HCE paths index the same slots):

    T = (a, m0, m2)    L = (m0, b, m1)    C = (m0, m1, m2)    R = (m2, m1, c)

Edges of the next level: each edge ``e = (p, q)`` splits into ``2 e = (p, V + e)`` and ``2 e + 1 = (V + e, q)``;
triangle ``t`` adds ``2 E + 3 t + k``: the edges of its C child. Nothing is sorted or hashed after level 0, so
refining a level costs a few gathers per face.
"""

from dataclasses import dataclass

import numpy as np

from ..common.errors import InvalidInputError
from ..common.topology import triangle_edges
from .loop_rules import SHARPNESS_INFINITE, child_sharpness

#: Child slot of the corner child at corners 0, 1, 2 (T, L, R); C is slot 2.
CORNER_SLOT = np.array([0, 1, 3])


@dataclass
class LoopLevel:
    """One level's topology and creases.

    triangles: (F, 3) int64; edges: (E, 2) int64 endpoints; face_edges: (F, 3) int64 edge of each local edge;
    edge_faces: (E, 2) int64 the faces on each side (second -1 on a boundary); edge_local: (E, 2) int64 the
    local edge index in those faces (-1); edge_sharpness: (E,) float32 OpenSubdiv sharpness (boundaries
    infinite); vertex_sharpness: (V,) float32; valence: (V,) int64 incident faces.
    """

    triangles: np.ndarray
    edges: np.ndarray
    face_edges: np.ndarray
    edge_faces: np.ndarray
    edge_local: np.ndarray
    edge_sharpness: np.ndarray
    vertex_sharpness: np.ndarray
    valence: np.ndarray

    @property
    def n_vertices(self):
        return len(self.valence)

    @property
    def boundary(self):
        """(E,) bool: edges with one face."""
        return self.edge_faces[:, 1] < 0


def coarse_level(triangles, n_vertices, creases=None, vertex_sharpness=None, sharp_corners=False):
    """The level-0 `LoopLevel` of a triangle mesh.

    triangles: (F, 3) int (validated). creases: ``(pairs (K, 2) int, sharpness (K,) float)`` or None; pairs
    that are not edges of the triangles are ignored. vertex_sharpness: (V,) float or None. sharp_corners:
    boundary vertices with a single face are corners (OpenSubdiv's VTX_BOUNDARY_EDGE_AND_CORNER).
    Raises `InvalidInputError` for an edge with more than two faces.
    """
    tris = np.asarray(triangles, dtype=np.int64)
    edges, face_edges, _ = triangle_edges(tris)
    n_e = len(edges)
    flat = face_edges.ravel().astype(np.int64)
    count = np.bincount(flat, minlength=n_e)
    if np.any(count > 2):
        bad = int(np.count_nonzero(count > 2))
        raise InvalidInputError(
            f"{bad} edge(s) are shared by more than two faces (non-manifold); Loop subdivision needs each edge "
            f"between at most two faces. Select them with Select > Select All by Trait > Non Manifold."
        )
    order = np.argsort(flat, kind="stable")
    starts = np.cumsum(count) - count
    edge_faces = np.full((n_e, 2), -1, np.int64)
    edge_local = np.full((n_e, 2), -1, np.int64)
    edge_faces[:, 0], edge_local[:, 0] = np.divmod(order[starts], 3)
    two = count == 2
    edge_faces[two, 1], edge_local[two, 1] = np.divmod(order[starts[two] + 1], 3)

    sharp = np.zeros(n_e, np.float32)
    if creases is not None and len(creases[0]):
        pairs = np.asarray(creases[0], dtype=np.int64).reshape(-1, 2)
        values = np.asarray(creases[1], dtype=np.float32)
        keys = edges[:, 0].astype(np.int64) * n_vertices + edges[:, 1]
        want = pairs.min(axis=1) * n_vertices + pairs.max(axis=1)
        at = np.minimum(np.searchsorted(keys, want), n_e - 1)
        found = keys[at] == want
        np.maximum.at(sharp, at[found], values[found])
    sharp[~two] = SHARPNESS_INFINITE
    valence = np.bincount(tris.ravel(), minlength=n_vertices).astype(np.int64)
    vs = np.zeros(n_vertices, np.float32) if vertex_sharpness is None else np.asarray(vertex_sharpness, np.float32)
    vs = vs.copy()
    if sharp_corners:
        on_boundary = np.zeros(n_vertices, bool)
        on_boundary[edges[~two].ravel()] = True
        vs[on_boundary & (valence == 1)] = SHARPNESS_INFINITE
    return LoopLevel(tris, edges.astype(np.int64), face_edges.astype(np.int64), edge_faces, edge_local, sharp, vs,
                     valence)


def _half(lv, e, corner_vertex):
    """Id of the half of edge ``e`` (K,) that touches ``corner_vertex`` (K,) on the next level."""
    return 2 * e + (lv.edges[e, 0] != corner_vertex)


def refine_level(lv):
    """The next `LoopLevel` (4 F triangles, V + E vertices, 2 E + 3 F edges), computed without sorting."""
    n_f, n_v, n_e = len(lv.triangles), lv.n_vertices, len(lv.edges)
    t, fe = lv.triangles, lv.face_edges
    a, b, c = t[:, 0], t[:, 1], t[:, 2]
    m0, m1, m2 = n_v + fe[:, 0], n_v + fe[:, 1], n_v + fe[:, 2]
    tris = np.empty((n_f, 4, 3), np.int64)
    tris[:, 0] = np.stack([a, m0, m2], axis=1)
    tris[:, 1] = np.stack([m0, b, m1], axis=1)
    tris[:, 2] = np.stack([m0, m1, m2], axis=1)
    tris[:, 3] = np.stack([m2, m1, c], axis=1)

    inner = 2 * n_e + 3 * np.arange(n_f, dtype=np.int64)  # + k: edges (m0, m1), (m1, m2), (m2, m0)
    face_edges = np.empty((n_f, 4, 3), np.int64)
    face_edges[:, 0] = np.stack([_half(lv, fe[:, 0], a), inner + 2, _half(lv, fe[:, 2], a)], axis=1)
    face_edges[:, 1] = np.stack([_half(lv, fe[:, 0], b), _half(lv, fe[:, 1], b), inner], axis=1)
    face_edges[:, 2] = np.stack([inner, inner + 1, inner + 2], axis=1)
    face_edges[:, 3] = np.stack([inner + 1, _half(lv, fe[:, 1], c), _half(lv, fe[:, 2], c)], axis=1)

    edges = np.empty((2 * n_e + 3 * n_f, 2), np.int64)
    mid = n_v + np.arange(n_e, dtype=np.int64)
    edges[0 : 2 * n_e : 2] = np.stack([lv.edges[:, 0], mid], axis=1)
    edges[1 : 2 * n_e : 2] = np.stack([mid, lv.edges[:, 1]], axis=1)
    edges[2 * n_e :] = np.stack([m0, m1, m1, m2, m2, m0], axis=1).reshape(-1, 2)

    # Faces beside each half edge: in old face f with local edge k, the half at endpoint p lies in the corner
    # child of p's corner, at local index k.
    edge_faces = np.full((len(edges), 2), -1, np.int64)
    edge_local = np.full((len(edges), 2), -1, np.int64)
    for side in (0, 1):
        f, k = lv.edge_faces[:, side], lv.edge_local[:, side]
        ok = f >= 0
        f, k = f[ok], k[ok]
        e = np.flatnonzero(ok)
        for end in (0, 1):
            corner = np.where(t[f, k] == lv.edges[e, end], k, (k + 1) % 3)
            edge_faces[2 * e + end, side] = 4 * f + CORNER_SLOT[corner]
            edge_local[2 * e + end, side] = k
    # Inner edge k of face f: the C child at local k, and the corner child L (k=0, local 2), R (k=1, local 0) or
    # T (k=2, local 1).
    f = np.arange(n_f, dtype=np.int64)
    for k, (slot, local) in enumerate(((1, 2), (3, 0), (0, 1))):
        edge_faces[inner + k, 0], edge_local[inner + k, 0] = 4 * f + 2, k
        edge_faces[inner + k, 1], edge_local[inner + k, 1] = 4 * f + slot, local

    sharp = np.zeros(len(edges), np.float32)
    sharp[: 2 * n_e] = np.repeat(child_sharpness(lv.edge_sharpness), 2)
    valence = np.concatenate([lv.valence, np.where(lv.boundary, 3, 6)])
    vs = np.concatenate([child_sharpness(lv.vertex_sharpness), np.zeros(n_e, np.float32)])
    return LoopLevel(tris.reshape(-1, 3), edges, face_edges.reshape(-1, 3), edge_faces, edge_local, sharp, vs,
                     valence)


def level_counts(n_vertices, n_edges, n_faces, levels):
    """(vertices, edges, faces) after ``levels`` uniform Loop steps: V' = V + E, E' = 2 E + 3 F, F' = 4 F."""
    for _ in range(int(levels)):
        n_vertices, n_edges, n_faces = n_vertices + n_edges, 2 * n_edges + 3 * n_faces, 4 * n_faces
    return n_vertices, n_edges, n_faces

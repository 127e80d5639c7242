"""The edge structure of one Loop level, built once for the coarse mesh and then refined analytically.

Local edge ``k`` of a triangle runs from corner ``k`` to corner ``k + 1``. A level's vertices are the previous
level's vertices (same ids) followed by one vertex per edge (id ``V + e``). Triangle ``t = (a, b, c)`` with edge
vertices ``m0 = m_ab, m1 = m_bc, m2 = m_ca`` has four children, numbered ``4 t + slot`` in [Concheiro et al.]'s T/L/C/R
order ([Concheiro et al., correction 4]; the colour encoding's paths index the same slots):

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


@dataclass
class LoopLevel:
    """One level's topology and creases.

    triangles: (F, 3) int32; edges: (E, 2) int32 endpoints; face_edges: (F, 3) int32 edge of each local edge;
    flip: (F, 3) bool, the local edge runs from ``edges[e, 1]`` to ``edges[e, 0]``; side: (F, 3) bool, the face
    is the edge's second face; boundary: (E,) bool, edges with one face; edge_sharpness: (E,) float32
    OpenSubdiv sharpness (boundaries infinite); vertex_sharpness: (V,) float32; valence: (V,) int64 incident
    faces.
    """

    triangles: np.ndarray
    edges: np.ndarray
    face_edges: np.ndarray
    flip: np.ndarray
    side: np.ndarray
    boundary: np.ndarray
    edge_sharpness: np.ndarray
    vertex_sharpness: np.ndarray
    valence: np.ndarray

    @property
    def n_vertices(self):
        return len(self.valence)

    def opposite(self):
        """(E, 2) int64: the vertex opposite each edge in its first and second face (the first again on a
        boundary)."""
        opp = np.empty((len(self.edges), 2), np.int64)
        opp[self.face_edges.ravel(), self.side.ravel().view(np.int8)] = self.triangles[:, [2, 0, 1]].ravel()
        opp[self.boundary, 1] = opp[self.boundary, 0]
        return opp


def coarse_level(triangles, n_vertices, creases=None, vertex_sharpness=None, sharp_corners=False):
    """The level-0 `LoopLevel` of a triangle mesh.

    triangles: (F, 3) int (validated). creases: ``(pairs (K, 2) int, sharpness (K,) float)`` or None; pairs
    that are not edges of the triangles are ignored. vertex_sharpness: (V,) float or None. sharp_corners:
    boundary vertices with a single face are corners (OpenSubdiv's VTX_BOUNDARY_EDGE_AND_CORNER).
    Raises `InvalidInputError` for an edge with more than two faces.
    """
    tris = np.asarray(triangles, dtype=np.int64)
    edges, face_edges, flipped = triangle_edges(tris)
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
    side = np.zeros(len(flat), bool)
    two = count == 2
    side[order[starts[two] + 1]] = True

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
    return LoopLevel(tris.astype(np.int32), edges.astype(np.int32), face_edges.astype(np.int32), flipped,
                     side.reshape(-1, 3), ~two, sharp, vs, valence)


# Children of a face, per slot (T, L, C, R) and local edge: the parent local edge it is a half of (-1: an inner
# edge).
_HALF_OF = np.array([[0, -1, 2], [0, 1, -1], [-1, -1, -1], [-1, 1, 2]])


_TRIANGLE_PATTERN = np.array([0, 3, 5, 3, 1, 4, 3, 4, 5, 5, 4, 2])  # columns of (a, b, c, m0, m1, m2) per child
_EDGE_PATTERN = np.array([0, 8, 5, 3, 1, 6, 6, 7, 8, 7, 4, 2])  # columns of (start0..2, end0..2, inner0..2)


def refine_level(lv, final=False):
    """The next `LoopLevel` (4 F triangles, V + E vertices, 2 E + 3 F edges), computed without sorting, int32.
    final: only triangles, edges, face_edges and edge_sharpness (the last level: nothing is refined from it)."""
    n_f, n_v, n_e = len(lv.triangles), lv.n_vertices, len(lv.edges)
    i32 = np.int32
    fe = lv.face_edges
    cols = np.empty((n_f, 9), i32)
    cols[:, :3] = lv.triangles
    np.add(fe, n_v, out=cols[:, 3:6])  # m0 = m_ab, m1 = m_bc, m2 = m_ca
    tris = np.take(cols[:, :6], _TRIANGLE_PATTERN, axis=1).reshape(-1, 3)

    # Halves: local edge k of face f (corner k -> k + 1) is edge e; its half at corner k is 2 e + flip, at
    # corner k + 1 it is 2 e + 1 - flip. Inner edges 2 E + 3 f + k: (m0, m1), (m1, m2), (m2, m0).
    m = cols[:, 3:6].copy()
    np.multiply(fe, 2, out=cols[:, 3:6])
    cols[:, 3:6] += lv.flip
    np.multiply(fe, 2, out=cols[:, 6:9])
    cols[:, 6:9] += 1
    cols[:, 6:9] -= lv.flip
    cols3 = np.empty((n_f, 12), i32)
    cols3[:, :6] = cols[:, 3:9]
    inner = cols3[:, 6:9]
    inner[:] = np.arange(2 * n_e, 2 * n_e + 3 * n_f, 3, dtype=i32)[:, None]
    inner += np.arange(3, dtype=i32)
    face_edges = np.take(cols3[:, :9], _EDGE_PATTERN, axis=1).reshape(-1, 3)

    edges = np.empty((2 * n_e + 3 * n_f, 2), i32)
    halves = edges[: 2 * n_e].reshape(n_e, 2, 2)
    halves[:, 0, 0] = lv.edges[:, 0]
    halves[:, 1, 1] = lv.edges[:, 1]
    halves[:, 0, 1] = halves[:, 1, 0] = np.arange(n_v, n_v + n_e, dtype=i32)
    inner_edges = edges[2 * n_e :].reshape(n_f, 3, 2)
    inner_edges[:, :, 0] = m
    inner_edges[:, :, 1] = m[:, [1, 2, 0]]
    sharp = np.repeat(child_sharpness(lv.edge_sharpness), 2)
    sharp = np.concatenate([sharp, np.zeros(3 * n_f, np.float32)])
    if final:
        return LoopLevel(tris, edges, face_edges, None, None, None, sharp, None, None)

    # Halves keep their parent's direction and side; the C child is the first face of every inner edge and runs
    # along it, the corner child is the second and runs against it.
    half = _HALF_OF >= 0
    of = np.maximum(_HALF_OF, 0)
    new_flip = np.where(half, lv.flip[:, of], np.arange(4)[:, None] != 2).reshape(-1, 3)
    new_side = np.where(half, lv.side[:, of], np.arange(4)[:, None] != 2).reshape(-1, 3)
    boundary = np.concatenate([np.repeat(lv.boundary, 2), np.zeros(3 * n_f, bool)])
    valence = np.concatenate([lv.valence, np.where(lv.boundary, 3, 6)])
    vs = np.concatenate([child_sharpness(lv.vertex_sharpness), np.zeros(n_e, np.float32)])
    return LoopLevel(tris, edges, face_edges, new_flip, new_side, boundary, sharp, vs, valence)


def level_counts(n_vertices, n_edges, n_faces, levels):
    """(vertices, edges, faces) after ``levels`` uniform Loop steps: V' = V + E, E' = 2 E + 3 F, F' = 4 F."""
    for _ in range(int(levels)):
        n_vertices, n_edges, n_faces = n_vertices + n_edges, 2 * n_edges + 3 * n_faces, 4 * n_faces
    return n_vertices, n_edges, n_faces

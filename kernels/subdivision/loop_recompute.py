"""[Concheiro et al.]'s recomputation model: every coarse triangle subdivided on its own from its
1-ring alone, with no sharing between triangles, the shared vertices recomputed by each triangle that touches them.

A triangle's patch is every coarse triangle sharing a vertex with it (n0 + n1 + n2 - 6 of them in a closed mesh,
[Concheiro et al.]), renumbered in the order of the global ids. The patch is subdivided with `loop.loop_step`; Loop's
support keeps the triangle's own sub-triangles exact although the patch's outer ring has no neighbours. The
renumbering keeps every sum in the order the whole-mesh reference uses (edges by id, opposite vertices by id),
so a vertex on a shared coarse edge comes out bit for bit the same from both triangles, and the same as the
reference (`loop.loop_subdivide`): the tests check both, and that the order the triangles are taken in changes
nothing. numpy here is a reference, not a fast path: one patch at a time (bench/subdivision.py, B4).
"""

import numpy as np

from ..common.errors import InvalidInputError
from ..common.topology import validate_triangles
from .loop import BOUNDARY_RULES, MAX_LEVELS, loop_step
from .loop_rules import correction_table
from .loop_topology import coarse_level, refine_level


def one_ring(triangles, n_vertices):
    """For each triangle, the triangles sharing a vertex with it (itself included), sorted: a list of (k,) int64."""
    tris = np.asarray(triangles, np.int64)
    owner = np.repeat(np.arange(len(tris)), 3)
    order = np.argsort(tris.ravel(), kind="stable")
    starts = np.concatenate([[0], np.cumsum(np.bincount(tris.ravel(), minlength=n_vertices))])
    faces_of = owner[order]
    return [np.unique(np.concatenate([faces_of[starts[v] : starts[v + 1]] for v in t])) for t in tris]


class Recomputation:
    """Loop subdivision per coarse triangle.

    positions: (V, D) float64 vertex data; triangles: (F, 3) int; levels: 1..MAX_LEVELS; creases:
    ``(pairs (K, 2), sharpness (K,))`` or None; vertex_sharpness: (V,) or None; boundary: as `loop.loop_subdivide`.
    """

    def __init__(self, positions, triangles, levels, creases=None, vertex_sharpness=None, boundary="EDGE_ONLY"):
        self.values = np.asarray(positions, np.float64)
        if self.values.ndim == 1:
            self.values = self.values[:, None]
        self.triangles = validate_triangles(triangles, len(self.values)).astype(np.int64)
        self.levels = int(levels)
        if not 1 <= self.levels <= MAX_LEVELS:
            raise InvalidInputError(f"Loop levels must lie in 1..{MAX_LEVELS}; got {levels}")
        if boundary not in BOUNDARY_RULES:
            raise InvalidInputError(f"Unknown boundary rule {boundary!r}; expected one of {BOUNDARY_RULES}")
        self.boundary = boundary
        self.creases = creases
        n_v = len(self.values)
        self.vertex_sharpness = np.zeros(n_v, np.float32) if vertex_sharpness is None else np.asarray(
            vertex_sharpness, np.float32)
        self.rings = one_ring(self.triangles, n_v)
        # the welded output's numbering: the whole-mesh topology, refined (no values)
        lv = coarse_level(self.triangles, n_v, creases, self.vertex_sharpness, boundary == "EDGE_AND_CORNER")
        self.n_coarse_edges = len(lv.edges)
        for step in range(self.levels):
            lv = refine_level(lv, final=step == self.levels - 1)
        self.output_triangles = lv.triangles
        self.n_out = int(lv.triangles.max()) + 1

    def local_patch(self, t):
        """Coarse triangle ``t``'s 1-ring as a mesh of its own: (global ids (P,) of its points, sorted, so the
        renumbering keeps the global order; its triangles (k, 3) in local ids, in global face order; the creases
        among its points ``(pairs, sharpness)`` in local ids, or None)."""
        ring = self.rings[t]
        verts = np.unique(self.triangles[ring])
        local = np.searchsorted(verts, self.triangles[ring])
        creases = None
        if self.creases is not None and len(self.creases[0]):
            pairs = np.asarray(self.creases[0], np.int64).reshape(-1, 2)
            keep = np.isin(pairs, verts).all(axis=1)
            creases = (np.searchsorted(verts, pairs[keep]), np.asarray(self.creases[1])[keep])
        return verts, local, creases

    def patch(self, t):
        """Coarse triangle ``t`` subdivided from its 1-ring alone: (global vertex ids (4^L, 3) of its sub-triangles,
        their values (4^L, 3, D) float64)."""
        ring = self.rings[t]
        verts, local, creases = self.local_patch(t)
        lv = coarse_level(local, len(verts), creases, self.vertex_sharpness[verts],
                          self.boundary == "EDGE_AND_CORNER")
        values = self.values[verts]
        for step in range(self.levels):
            values = loop_step(lv, values, correction_table(lv.valence.max(initial=6)))
            lv = refine_level(lv, final=step == self.levels - 1)
        k = int(np.searchsorted(ring, t))  # t's place among the patch's faces
        n_sub = 4**self.levels
        own = lv.triangles[k * n_sub : (k + 1) * n_sub]
        return self.output_triangles[t * n_sub : (t + 1) * n_sub], values[own]

    def run(self, order=None, check=True):
        """Every coarse triangle's patch, in ``order`` (default: by id), welded into (V_L, D) float64. check:
        assert that every vertex written by several triangles got the same bits from each."""
        out = np.full((self.n_out, self.values.shape[1]), np.nan)
        written = np.zeros(self.n_out, bool)
        for t in range(len(self.triangles)) if order is None else order:
            ids, values = self.patch(int(t))
            ids, values = ids.ravel(), values.reshape(-1, values.shape[-1])
            if check:
                seen = written[ids]
                if not np.array_equal(out[ids[seen]], values[seen]):
                    raise AssertionError(f"coarse triangle {t} recomputed a shared vertex differently")
            out[ids] = values
            written[ids] = True
        loose = np.flatnonzero(~written[: len(self.values)])  # vertices in no face keep their place
        out[loose] = self.values[loose]
        return out

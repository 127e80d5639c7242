"""Levels of Bézier patches (`patch_levels`): curvature, distance, projected edge length and the tolerance's first
guess from the control points, and where the tolerance's steps go along each direction (`patch_spacing`)."""

from dataclasses import dataclass

import numpy as np

from ...common.curves import step_spacing
from ...common.curves.rational_bezier import (
    bernstein,
    cartesian,
    chord_deviation,
    steps_for,
)
from ...common.errors import InvalidInputError
from ...common.level_metrics import curvature_level, curve_kappa, distance_level, projected_sphere_levels
from ...common.partition import MAX_LEVEL
from .nets import COLLAPSED, check_patches, tensor_grid

METRICS = ("CURVATURE", "DISTANCE", "EDGE_LENGTH", "TOLERANCE")

@dataclass(frozen=True)
class PatchLod:
    """How levels are chosen: metrics, some of CURVATURE, DISTANCE, EDGE_LENGTH, TOLERANCE (combined by maximum);
    max_level (≤ 64, the curvature metric's cap t_tessmax); inner_rows ALL or INTERIOR; near, far, mapping (LINEAR or
    INVERSE): the distance map; edge_pixels: the projected-edge metric's segment length on screen; degenerate:
    what a row of the net that collapses to one point (κ⁺ = 0/0) counts for the inner levels: CAP ([Nellmedin 2014]'s
    GPU, and what makes the teapot's knob and base its finest patches; [Nellmedin 2014, correction 4]) or ZERO (no
    bend); tolerance: the largest distance between the mesh and the surface (scene units) for TOLERANCE."""

    metrics: tuple = ("CURVATURE",)
    max_level: int = 32
    inner_rows: str = "ALL"
    near: float = 1.0
    far: float = 20.0
    mapping: str = "LINEAR"
    edge_pixels: float = 10.0
    degenerate: str = "CAP"
    tolerance: float = 0.001

    def __post_init__(self):
        if not self.metrics or not set(self.metrics) <= set(METRICS):
            raise InvalidInputError(f"metrics must be some of {', '.join(METRICS)}; got {self.metrics!r}")
        if not (np.isfinite(self.edge_pixels) and self.edge_pixels > 0):
            raise InvalidInputError(f"Edge Pixels must be a positive number; got {self.edge_pixels!r}")
        if not (np.isfinite(self.tolerance) and self.tolerance > 0):
            raise InvalidInputError(f"Tolerance must be a positive distance; got {self.tolerance!r}")
        if self.degenerate not in ("CAP", "ZERO"):
            raise InvalidInputError(f"degenerate must be CAP or ZERO; got {self.degenerate!r}")
        if self.inner_rows not in ("ALL", "INTERIOR"):
            raise InvalidInputError(f"inner_rows must be ALL or INTERIOR; got {self.inner_rows!r}")
        if not 1 <= self.max_level <= MAX_LEVEL:
            raise InvalidInputError(f"Max Level must be from 1 to {MAX_LEVEL}; got {self.max_level!r}")

@dataclass
class Spacing:
    """Where the steps fall, for the tolerance (`kernels.common.curves.step_spacing`, made by `patch_spacing`): edge
    (E, M + 1) each shared side's table in its canonical direction; inner (P, 2, M + 1) each patch's tables along u
    and along v. A side's table is its chain's, as are the inner tables of the patches beside it along it, so they
    put their points at the same parameters."""

    edge: np.ndarray
    inner: np.ndarray

    def side_params(self, level):
        """Each edge's parameters at its level (E,) in its canonical direction: (E, max level + 1) float64, padded
        with 1 past each edge's end."""
        return step_spacing.padded_params(self.edge, level)

    def of(self, ps):
        """The spacing of patches ps (p,) alone (their inner tables; the edges' all)."""
        return Spacing(self.edge, self.inner[ps])

    def inner_params(self, ps, axis, n):
        """Parameters (p, n + 1) of n steps along axis (0: u, 1: v) of patches ps (p,)."""
        return step_spacing.params(self.inner[ps, axis], int(n))

def patch_spacing(h, edges, lines=9):
    """`Spacing` of nets h (P, k, k, 4) and their `PatchEdges`. A direction's density is the largest of its
    ``lines`` iso-lines' (`kernels.common.curves.step_spacing.bend_density`), boundaries included. Patches that share a
    side share their steps along it: the directions linked through shared sides (`direction_chains`) take the
    largest density of the chain, each read in its own direction, and each side its chain's, so a side's points
    are where the inner grids beside it put theirs."""
    k, m = h.shape[1], step_spacing.SAMPLES
    t = np.linspace(0.0, 1.0, 2 * m + 1)
    across = np.linspace(0.0, 1.0, lines)
    grid_u = cartesian(tensor_grid(bernstein(t, k - 1), bernstein(across, k - 1), h))  # (P, lines, 2M+1, 3)
    grid_v = cartesian(tensor_grid(bernstein(across, k - 1), bernstein(t, k - 1), h))  # (P, 2M+1, lines, 3)
    rho_u = step_spacing.bend_density(grid_u.reshape(-1, len(t), 3)).reshape(len(h), lines, m).max(axis=1)
    rho_v = step_spacing.bend_density(grid_v.transpose(0, 2, 1, 3).reshape(-1, len(t), 3))
    rho = np.stack([rho_u, rho_v.reshape(len(h), lines, m).max(axis=1)], axis=1)  # (P, 2, M)
    chain, flip, edge_chain, edge_flip, two_way = direction_chains(edges, len(h))
    chain_rho = np.zeros((len(two_way), m))
    np.maximum.at(chain_rho, chain.ravel(), np.where(flip[..., None], rho[..., ::-1], rho).reshape(-1, m))
    chain_rho[two_way] = np.maximum(chain_rho[two_way], chain_rho[two_way, ::-1])
    inner = chain_rho[chain]
    inner = np.where(flip[..., None], inner[..., ::-1], inner)
    edge = chain_rho[edge_chain]
    edge = np.where(edge_flip[:, None], edge[:, ::-1], edge)
    return Spacing(step_spacing.cumulative(edge),
                   step_spacing.cumulative(inner.reshape(-1, m)).reshape(len(h), 2, m + 1))

def direction_chains(edges, count):
    """The patches' directions linked through their shared sides (a BOTTOM or TOP side runs along u, a RIGHT or
    LEFT one along v; a pole links nothing), by union-find with orientation. Returns chain (P, 2) int64 of each
    patch's u and v, flip (P, 2) bool (runs against its chain), edge_chain (E,) and edge_flip (E,) of each shared
    side in its canonical direction, two_way (C,) bool: a chain met in both orientations (a twisted loop), whose
    steps must then read the same both ways."""
    n_e = len(edges.control)
    parent = list(range(2 * count + n_e))
    parity = [False] * len(parent)
    twisted = set()

    def find(a):
        path = []
        while parent[a] != a:
            path.append(a)
            a = parent[a]
        flip = False
        for b in reversed(path):  # compress, keeping each node's orientation to the root
            flip ^= parity[b]
            parent[b], parity[b] = a, flip
        return a

    for p in range(count):
        for side in range(4):
            e = int(edges.edge[p, side])
            if edges.collapsed[e]:
                continue
            a, b = 2 * p + side % 2, 2 * count + e
            ra, rb = find(a), find(b)
            want = parity[a] ^ parity[b] ^ bool(edges.reversed[p, side])
            if ra == rb:
                if want:
                    twisted.add(ra)
            else:
                parent[rb], parity[rb] = ra, want
                if rb in twisted:
                    twisted.add(ra)
    roots = [find(a) for a in range(len(parent))]
    _, label = np.unique(roots, return_inverse=True)
    flips = np.array(parity)
    two_way = np.zeros(int(label.max()) + 1, bool)
    two_way[label[[find(r) for r in twisted]]] = True
    return (label[:2 * count].reshape(count, 2), flips[:2 * count].reshape(count, 2), label[2 * count:],
            flips[2 * count:], two_way)

def _eq45(kappa, max_level, k):
    return np.ceil(curvature_level(kappa, n_control=k, t_max=float(max_level))).astype(np.int64)

def diagonal_kappa(control):
    """Eq. 4.6 per cell of each net: ½ |P[i+1,j+1] + P[i,j] - P[i+1,j] - P[i,j+1]| / min(diagonals), the largest
    of the cells: (P, k, k, 3) -> (P,). A cell whose diagonals both vanish counts as 0 (nothing to split)."""
    c = np.asarray(control, np.float64)
    a, b, d, e = c[:, :-1, :-1], c[:, 1:, 1:], c[:, 1:, :-1], c[:, :-1, 1:]
    num = 0.5 * np.linalg.norm(b + a - d - e, axis=-1)
    den = np.minimum(np.linalg.norm(b - a, axis=-1), np.linalg.norm(e - d, axis=-1))
    k = np.divide(num, den, out=np.where(num > 0, np.inf, 0.0), where=den > 0)
    return k.reshape(len(c), -1).max(axis=1)

def _polygon_length(points):
    """Lengths of control polygons (..., n, 3) -> (...): an upper bound of their curves' lengths."""
    return np.linalg.norm(np.diff(points, axis=-2), axis=-1).sum(axis=-1)

def _direction_deviation(h, steps=16, lines=9, spacing=None):
    """How far each patch's iso-lines stray from their chords at ``steps`` steps
    (`kernels.common.curves.rational_bezier.chord_deviation`; equal, or by the patches' `Spacing`): along u (``lines``
    lines of constant v) and along v: (P, 2) float64."""
    k = h.shape[1]
    b = bernstein(np.linspace(0.0, 1.0, lines), k - 1)  # (lines, k)
    along_u = np.einsum("aj,pijc->paic", b, h)  # the iso-lines' control points (P, lines, k, 4)
    along_v = np.einsum("ai,pijc->pajc", b, h)
    out = []
    for axis, c in enumerate((along_u, along_v)):
        table = None if spacing is None else np.repeat(spacing.inner[:, axis], lines, axis=0)
        out.append(chord_deviation(c.reshape(-1, k, 4), steps, table).reshape(len(h), lines).max(axis=1))
    return np.stack(out, axis=1)

def patch_levels(control, edges, lod, camera=None, spacing=None):
    """Levels: (edge levels (E,) int64, inner levels (P, 2) int64: steps along u and along v) in [1, max_level].
    Curvature, distance and edge length give the same inner level both ways; the tolerance gives each direction
    its own, for steps spaced by ``spacing`` (a `Spacing`; None: equal steps). camera: a
    `kernels.common.camera.Camera` in the patches' space, for DISTANCE and EDGE_LENGTH."""
    h = check_patches(control)
    c = cartesian(h)
    k = h.shape[1]
    ec = cartesian(edges.control)
    edge_level = np.ones(len(edges.control), np.int64)
    inner = np.ones(len(c), np.int64)
    if (set(lod.metrics) & {"DISTANCE", "EDGE_LENGTH"}) and camera is None:
        raise InvalidInputError("Distance and edge-length levels need a camera")
    if "CURVATURE" in lod.metrics:
        edge_level = np.maximum(edge_level, _eq45(curve_kappa(ec), lod.max_level, k))
        rows = slice(None) if lod.inner_rows == "ALL" or k < 4 else slice(1, k - 1)
        along_u, along_v = c[:, :, rows].transpose(0, 2, 1, 3), c[:, rows, :]  # (P, rows, k, 3) each
        k_u, k_v = curve_kappa(along_u), curve_kappa(along_v)
        if lod.degenerate == "CAP":
            size = np.abs(c).max() + 1.0
            one_u = np.all(np.linalg.norm(along_u - along_u[:, :, :1], axis=-1) <= COLLAPSED * size, axis=2)
            one_v = np.all(np.linalg.norm(along_v - along_v[:, :, :1], axis=-1) <= COLLAPSED * size, axis=2)
            k_u = np.where(one_u, np.inf, k_u)
            k_v = np.where(one_v, np.inf, k_v)
        k_u, k_v = k_u.max(axis=1), k_v.max(axis=1)
        k_x = diagonal_kappa(c)
        diag = k_x > np.maximum(k_u, k_v)
        k_in = np.where(diag, k_x, np.maximum(k_u, k_v))
        inner = np.maximum(inner, _eq45(k_in, lod.max_level, k))
    if "EDGE_LENGTH" in lod.metrics:  # a sphere of the control polygon's length, at its centroid (§4.4)
        view = np.asarray(camera.view, np.float64)

        def projected(centre, length):
            m = centre @ view[:3, :3].T + view[:3, 3]
            t = projected_sphere_levels(m, length, camera.projection, camera.height, lod.edge_pixels,
                                        float(lod.max_level))
            return np.ceil(t).astype(np.int64)

        edge_level = np.maximum(edge_level, projected(ec.mean(axis=1), _polygon_length(ec)))
        size = np.maximum(_polygon_length(c).max(axis=1), _polygon_length(c.transpose(0, 2, 1, 3)).max(axis=1))
        inner = np.maximum(inner, projected(c.reshape(len(c), -1, 3).mean(axis=1), size))
    if "DISTANCE" in lod.metrics:
        eye = camera.eye
        d_edge = np.linalg.norm(ec - eye, axis=-1).min(axis=1)
        d_in = np.linalg.norm(c.reshape(len(c), -1, 3).mean(axis=1) - eye, axis=-1)

        def dist(d):
            return np.ceil(distance_level(d, lod.near, lod.far, float(lod.max_level), lod.mapping)).astype(np.int64)

        edge_level = np.maximum(edge_level, dist(d_edge))
        inner = np.maximum(inner, dist(d_in))
    if "TOLERANCE" in lod.metrics:
        side_dev = chord_deviation(edges.control, np.full(len(ec), 16), None if spacing is None else spacing.edge)
        edge_level = np.maximum(edge_level, steps_for(side_dev, 16, lod.tolerance, lod.max_level))
    inner = np.stack([inner, inner], 1)
    if "TOLERANCE" in lod.metrics:  # each direction half the tolerance: a cell's diagonal strays about their sum
        inner = np.maximum(inner, steps_for(_direction_deviation(h, spacing=spacing), 16, 0.5 * lod.tolerance,
                                            lod.max_level))
    return np.minimum(edge_level, lod.max_level), np.minimum(inner, lod.max_level)

def _sides_keep_up(edge_levels, inner, edges):
    """Edge levels raised to the steps of the patches beside them in the side's direction (a bottom or top side
    runs along u, a left or right one along v); a pole stays one segment."""
    el = np.asarray(edge_levels, np.int64).copy()
    np.maximum.at(el, edges.edge[:, [0, 2]].ravel(), np.repeat(inner[:, 0], 2))
    np.maximum.at(el, edges.edge[:, [1, 3]].ravel(), np.repeat(inner[:, 1], 2))
    return np.where(edges.collapsed, 1, el)

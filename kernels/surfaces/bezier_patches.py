"""Rational Bézier patches of any degree tessellated with per-patch, per-boundary levels, welded with no
T-junction ([Nellmedin 2014, §4.3, §5.5.3]; the Utah teapot's kind of model, and every NURBS surface Blender holds once
`kernels.common.nurbs` has split it into patches).

A patch is its k x k homogeneous control net ``H[i, j] = (w x, w y, w z, w)`` (i along u, j along v; degree k - 1
in both directions: a direction of lower degree is raised exactly, `kernels.common.nurbs.degree_elevate`), and
``S(u, v) = Σ B_i(u) B_j(v) H[i, j]`` divided by its last coordinate. Polynomial patches may be given as (P, k, k, 3)
Cartesian nets (weights 1). Sides, in the pattern's order (`kernels.common.quad_pattern.pattern`): BOTTOM v = 0 (u
from 0 to 1), RIGHT u = 1 (v up), TOP v = 1 (u up), LEFT u = 0 (v up). A side is a rational curve of its k control
points only, so it is one edge shared by the patches that have those points: each edge is keyed by its control points
in a canonical direction, its level computed once from them and its points evaluated once, in that direction; a patch
reads them forwards or backwards. Corners are control points. Shared boundaries are therefore one set of vertices
(welded by construction) and no crack or T-junction can appear. A boundary that collapses to a point (the teapot's lid
top, a NURBS sphere's poles) gives the same point L + 1 times: such points are merged (the poles of all the patches
around one point become one vertex) and the triangles they flatten dropped. Such a collapsed row has κ⁺ = 0/0: it
counts as the cap by default, as [Nellmedin 2014]'s GPU did ([Nellmedin 2014, item 5; `PatchLod.degenerate`).

Levels (`patch_levels`), on the control points' Cartesian positions:
- curvature: a side's level from its own control polygon (eq. 4.5, min 2 (k - 1), max Max Level); the inner levels
  from the rows (u) and the columns (v) of the net (``inner_rows`` ALL, [Nellmedin 2014]'s §4.1.2, or INTERIOR, its
  §5.3.3: [Nellmedin 2014, correction 3]) and the cells' diagonal κ× (eq. 4.6): if the largest κ× exceeds both, it sets
  both;
- distance: a side from the smallest distance of its control points to the eye, the inner from the net's centroid,
  through the linear (or inverse) map between Near and Far;
- projected edge length (§4.4): a side as a sphere as wide as its control polygon is long, at its centroid, over
  Edge Pixels; the inside from the net's longest row or column at its centroid;
- tolerance (chordal deviation, scene units): the steps are spaced where the surface bends (`patch_spacing`:
  `kernels.common.step_spacing`, one table for every direction linked through shared sides, `direction_chains`); a
  side's level from the deviation of its chords at 16 steps, a direction's from its iso-lines', both scaled as the
  square root (the deviation of a chord falls with the square of its length); each inner grid is then fitted to a
  model measured on a 12 x 12 probe (`fitted_inner`), and every triangle is measured against the surface, before the
  mesh is made (the inner grids by `grid_deviation`, the strips along the sides by `rim_triangles`), raising the
  levels where it is still over (`TOLERANCE_ROUNDS` times at most), so the tolerance is met or the patches that
  cannot meet it within Max Level are named (and split, `tessellate`);
- any of these together: the largest. Levels are whole segment counts. The inside of a patch has a count of steps
  along u and one along v: the same (the larger) for curvature, distance and edge length, each its own for the
  tolerance.
"""

import logging
from dataclasses import dataclass, replace
from functools import cache, lru_cache

import numpy as np

from ..common import step_spacing, workers
from ..common.budget import Estimate, check_budget
from ..common.errors import InvalidInputError, OpenCLUnavailableError, TesseraError
from ..common.level_metrics import curvature_level, curve_kappa, distance_level, projected_sphere_levels
from ..common.opencl_runtime import backend_runtime
from ..common.partition import MAX_LEVEL
from ..common.quad_pattern import pattern, pattern_codes, strips, zip_by_params
from ..common.rational_bezier import (
    bernstein,
    bernstein_derivative,
    cartesian,
    chord_deviation,
    steps_for,
)
from . import patch_deviation_opencl, patch_split

METRICS = ("CURVATURE", "DISTANCE", "EDGE_LENGTH", "TOLERANCE")
#: Rounds of measuring the mesh against the surface and raising levels, for the tolerance.
TOLERANCE_ROUNDS = 16
#: Barycentric points where each triangle is measured against the surface: its edges' midpoints, its centroid and
#: the points halfway from the centroid to each corner (where the deviation of a smooth surface from a small
#: triangle is largest).
_B = np.array([[.5, .5, 0], [0, .5, .5], [.5, 0, .5], [1 / 3, 1 / 3, 1 / 3], [2 / 3, 1 / 6, 1 / 6],
               [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]])
#: `fitted_inner`'s model of a grid is measured at this many steps each way.
FIT_PROBE = 12
#: With spaced steps, `grid_deviation` measures patches together whose counts round up to the same multiple of this.
GRID_BUCKET = 8
#: `grid_deviation` measures at most this many cells at once (a few float64 arrays of 4 values a cell).
GRID_CELLS = 1 << 18
#: `fitted_inner` aims this far under the tolerance: the grids are measured again at the levels it gives, at the
#: same points, so only the model's error needs room.
FIT_AIM = 0.95
#: With the tolerance, how many times patches still over it at Max Level are split and the whole made again.
SPLIT_ROUNDS = 3
#: A side whose control points are all within this fraction of the model's size of its first is one point (a pole).
COLLAPSED = 1e-12


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
class PatchEdges:
    """The patches' sides as shared edges. control: (E, k, 4) each edge's homogeneous control points in its
    canonical direction; edge: (P, 4) the edge of each patch side; reversed: (P, 4) whether the side runs against
    it; collapsed: (E,) bool, the edge is one point (a pole); point: (E, 3) that point (the first control point's
    position, the same for every collapsed edge that meets there)."""

    control: np.ndarray
    edge: np.ndarray
    reversed: np.ndarray
    collapsed: np.ndarray = None
    point: np.ndarray = None


@dataclass
class Spacing:
    """Where the steps fall, for the tolerance (`kernels.common.step_spacing`, made by `patch_spacing`): edge
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
    ``lines`` iso-lines' (`kernels.common.step_spacing.bend_density`), boundaries included. Patches that share a
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


@dataclass
class PatchMesh:
    """positions (V, 3) float32; triangles (T, 3) int32; uv (V, 2) float32 and patch (V,) int64: where each vertex
    was evaluated (a shared vertex: its first patch); triangle_patch (T,) int64 and corner_uv (T, 3, 2) float32:
    each triangle's patch and its corners' (u, v) in it; normals (V, 3) float32: the surface's unit normal at each
    vertex. Oriented as Blender orients a NURBS surface's faces (its primitives face out): the normal along
    dS/dv x dS/du, the triangles clockwise in (u, v) (counter-clockwise seen from the normal's side)."""

    positions: np.ndarray
    triangles: np.ndarray
    uv: np.ndarray
    patch: np.ndarray
    triangle_patch: np.ndarray
    corner_uv: np.ndarray
    normals: np.ndarray = None


@dataclass
class Tessellation:
    """What `tessellate` made: mesh (`PatchMesh`); edge_levels (E,) and inner_levels (P, 2) int64; edges
    (`PatchEdges`); deviation (P,) float64: the largest distance measured between each patch's triangles and the
    surface (NaN when the tolerance was not asked for); unmet (K,) int64: the patches still over the tolerance at Max
    Level. With the tolerance a patch may have been split into parts (`kernels.surfaces.patch_split`): then the mesh,
    the levels, the deviation and unmet are the parts', parent (P',) int64 is each part's patch and box (P', 2, 2)
    its ((u0, u1), (v0, v1)) there."""

    mesh: PatchMesh
    edge_levels: np.ndarray
    inner_levels: np.ndarray
    edges: PatchEdges
    deviation: np.ndarray
    unmet: np.ndarray
    parent: np.ndarray = None
    box: np.ndarray = None

    def patch_uv(self, outer=None):
        """Each triangle's corners' (u, v) in its patch (not its part): (T, 3, 2) float64. outer (P, 2, 2): each
        patch's ((u0, u1), (v0, v1)) in something larger (its spline: `kernels.common.nurbs.PatchSet.box`): the
        corners' (u, v) there instead, (T, 3, 2) float32, each part's two boxes composed first."""
        if outer is None:
            b = self.box[self.mesh.triangle_patch][:, None]
            return b[..., 0] + self.mesh.corner_uv.astype(np.float64) * (b[..., 1] - b[..., 0])
        lo, size = self.box[:, :, 0], self.box[:, :, 1] - self.box[:, :, 0]
        o = np.asarray(outer, np.float64)[self.parent]
        o_lo, o_size = o[:, :, 0], o[:, :, 1] - o[:, :, 0]
        lo, size = o_lo + lo * o_size, size * o_size  # (P', 2): one affine map a part
        tp = self.mesh.triangle_patch
        return lo[tp].astype(np.float32)[:, None] + self.mesh.corner_uv * size[tp].astype(np.float32)[:, None]






def tensor_grid(b_u, b_v, h):
    """Homogeneous points of patches h (P, k, k, c) on a grid: b_u (U, k) and b_v (V, k) basis values along u and
    v -> (P, V, U, c) (row j at the j-th v). Two matrix products (`_contract_v_basis`, `_contract_u_basis`)."""
    return _contract_u_basis(_contract_v_basis(h, b_v), b_u).transpose(0, 2, 3, 1)


def homogeneous_nets(control):
    """(P, k, k, 4) homogeneous nets from (P, k, k, 3) Cartesian (weights 1) or (P, k, k, 4) homogeneous."""
    c = np.asarray(control, np.float64)
    if c.ndim == 4 and c.shape[-1] == 3:
        c = np.concatenate([c, np.ones(c.shape[:-1] + (1,))], axis=-1)
    return c


def evaluate(control, u, v):
    """Points of patches: control (P, k, k, 3 or 4), u and v (P, n) -> (P, n, 3)."""
    h = homogeneous_nets(control)
    k = h.shape[1]
    w = (bernstein(u, k - 1)[..., :, None] * bernstein(v, k - 1)[..., None, :]).reshape(np.shape(u) + (k * k,))
    p = np.matmul(w, h.reshape(len(h), k * k, 4))  # batched matrix products: far faster than einsum here
    return p[..., :3] / p[..., 3:]


def _point_and_normal(h, u, v):
    """Positions (N, 3) and unit normals (N, 3) of nets h (N, k, k, 4) at u, v (N,). A normal that vanishes (at a
    pole) is taken a little inside the patch, towards its centre."""
    d = h.shape[1] - 1

    def at(h, u, v):
        bu, bv = bernstein(u, d), bernstein(v, d)
        du, dv = bernstein_derivative(u, d), bernstein_derivative(v, d)
        with_bv = np.matmul(h.transpose(0, 1, 3, 2), bv[:, None, :, None])[..., 0]  # (n, k_u, c): Σ_j bv_j h_ij
        with_dv = np.matmul(h.transpose(0, 1, 3, 2), dv[:, None, :, None])[..., 0]
        s = np.matmul(bu[:, None], with_bv)[:, 0]
        su = np.matmul(du[:, None], with_bv)[:, 0]
        sv = np.matmul(bu[:, None], with_dv)[:, 0]
        w = s[:, 3:]
        p = s[:, :3] / w
        n = np.cross(su[:, :3] - p * su[:, 3:], sv[:, :3] - p * sv[:, 3:])
        return p, n

    p, n = at(h, u, v)
    length = np.linalg.norm(n, axis=1)
    scale = np.abs(h[..., :3] / h[..., 3:]).reshape(len(h), -1).max(axis=1) + 1.0
    weak = length <= 1e-9 * scale ** 2
    for step in (1e-4, 1e-3, 1e-2):
        if not weak.any():
            break
        _, n2 = at(h[weak], u[weak] + step * (0.5 - u[weak]), v[weak] + step * (0.5 - v[weak]))
        n[weak] = n2
        length = np.linalg.norm(n, axis=1)
        weak = length <= 1e-9 * scale ** 2
    n = n / np.where(length > 0, length, 1.0)[:, None]
    return p, n


def check_patches(control):
    """Validated homogeneous nets (P, k, k, 4) float64 of (P, k, k, 3) Cartesian or (P, k, k, 4) homogeneous
    control points, k from 2 to 7."""
    c = np.asarray(control, np.float64)
    if c.ndim != 4 or c.shape[1] != c.shape[2] or not 2 <= c.shape[1] <= 7 or c.shape[3] not in (3, 4) or len(c) == 0:
        raise InvalidInputError(f"Patches need (P, k, k, 3) or (P, k, k, 4) control points, k from 2 to 7; got "
                                f"{c.shape}")
    if not np.all(np.isfinite(c)):
        raise InvalidInputError("The surface has control points that are NaN or infinite")
    h = homogeneous_nets(c)
    if np.any(h[..., 3] <= 0):
        raise InvalidInputError("The surface has weights of zero or less; NURBS weights must be positive")
    return h




def _sides(h):
    """Each patch's four sides' homogeneous control points, in the sides' directions: (P, 4, k, 4)."""
    return np.stack([h[:, :, 0], h[:, -1, :], h[:, :, -1], h[:, 0, :]], axis=1)


def patch_edges(control):
    """Key every patch side by its control points: a `PatchEdges`."""
    h = check_patches(control)
    k = h.shape[1]
    flat = _sides(h).reshape(-1, k, 4)
    back = flat[:, ::-1]
    fwd_key, back_key = flat.reshape(len(flat), -1), back.reshape(len(flat), -1)
    # canonical: the lexicographically smaller of the two directions (exact comparison of the float64 values)
    diff = fwd_key != back_key
    first = np.where(diff.any(axis=1), diff.argmax(axis=1), 0)
    rows = np.arange(len(flat))
    rev = back_key[rows, first] < fwd_key[rows, first]
    canon = np.where(rev[:, None, None], back, flat)
    _, first_of, edge = np.unique(canon.reshape(len(canon), -1), axis=0, return_index=True, return_inverse=True)
    control_e = canon[first_of]
    pts = cartesian(control_e)
    size = np.abs(cartesian(h)).max() + 1.0
    collapsed = np.all(np.linalg.norm(pts - pts[:, :1], axis=-1) <= COLLAPSED * size, axis=1)
    point = pts[:, 0].copy()
    point[collapsed] = _cluster(point[collapsed], COLLAPSED * size * 16)
    return PatchEdges(control_e, edge.reshape(-1, 4), rev.reshape(-1, 4), collapsed, point)


def _cluster(points, tol):
    """Points (n, 3) with each group of near-equal ones (within tol) replaced by the group's first: (n, 3)."""
    out = points.copy()
    done = np.zeros(len(points), bool)
    for i in range(len(points)):  # few: one per pole side
        if done[i]:
            continue
        near = (np.linalg.norm(points - points[i], axis=1) <= tol) & ~done
        out[near] = points[i]
        done |= near
    return out


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
    (`kernels.common.rational_bezier.chord_deviation`; equal, or by the patches' `Spacing`): along u (``lines``
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


def triangle_deviation(control, mesh, which=None):
    """The largest distance between each triangle and the surface: (T,) float64. Each of `_B`'s barycentric points
    of a triangle is compared with the surface at the same barycentric point of its corners' (u, v) — the mesh's
    map to the surface — so this bounds the distance both ways where the points are dense enough. which: (T',)
    the triangles to measure (all by default); the result is theirs."""
    h = check_patches(control)
    which = np.arange(len(mesh.triangles)) if which is None else np.asarray(which, np.int64)
    return _deviation(h, mesh.positions.astype(np.float64)[mesh.triangles[which]],
                      mesh.corner_uv[which].astype(np.float64), mesh.triangle_patch[which])


def _deviation(h, corners, uv, patch, runtime=None):
    """`triangle_deviation` of triangles given by their corners' positions (T, 3, 3), (u, v) (T, 3, 2) and
    patch (T,): (T,) float64; on ``runtime``'s OpenCL device where it has double precision
    (`patch_deviation_opencl`)."""
    if patch_deviation_opencl.supports(runtime):
        return patch_deviation_opencl.triangle_deviation(runtime, h, corners, uv, patch, _B)
    on_mesh = np.matmul(_B, corners)
    at = np.matmul(_B, uv)
    out = np.empty(len(corners))
    for chunk in np.array_split(np.arange(len(corners)), max(1, len(corners) // 65536)):
        s = evaluate(h[patch[chunk]], at[chunk, :, 0], at[chunk, :, 1])
        out[chunk] = np.linalg.norm(on_mesh[chunk] - s, axis=-1).max(axis=1)
    return out


def rim_triangles(control, edge_levels, inner_levels, edges, spacing, which, runtime=None):
    """The triangles of patches ``which`` (p,) that reach a side of their patch, as `tessellate_patches` makes
    them (a triangle flattened at a pole dropped, its fan's corner (u, v) at the pole moved as there), without
    making the mesh: (corners (R, 3, 3) positions, (u, v) (R, 3, 2), both rounded to float32 as the mesh stores
    them, patch (R,) int64). The corners are evaluated on ``runtime``'s OpenCL device where it has double precision
    (`patch_deviation_opencl.points`)."""
    h = check_patches(control)
    el = np.asarray(edge_levels, np.int64)
    side_counts = el[edges.edge]
    n_in = _pattern_counts(inner_pairs(inner_levels, len(h)), side_counts)
    side_t = None if spacing is None else spacing.side_params(el)
    keys = np.concatenate([side_counts, n_in], axis=1)[which]
    classes, inverse = np.unique(keys, axis=0, return_inverse=True)
    uvs, patches = [], []
    for cls, key in enumerate(classes):
        ps = np.asarray(which)[inverse.ravel() == cls]
        key_t = tuple(int(x) for x in key)
        if spacing is None:
            tmpl = pattern(*key_t)
            on_rim = (tmpl < sum(key_t[:4])).any(axis=1)  # a corner on a side: corners and sides' points come first
            local = np.broadcast_to(_pattern_uv(key_t), (len(ps),) + _pattern_uv(key_t).shape)
            own = np.broadcast_to(tmpl[on_rim], (len(ps),) + tmpl[on_rim].shape)
        else:
            nu, nv = key_t[4], key_t[5]
            cells = (nu - 1) * (nv - 1) if nu > 1 and nv > 1 else 0
            jj, ii = np.divmod(np.arange(cells), max(nu - 1, 1))
            t_u, t_v = spacing.inner_params(ps, 0, nu), spacing.inner_params(ps, 1, nv)
            inner = np.stack([t_u[:, ii + 1], t_v[:, jj + 1]], axis=-1)
            local = _spaced_pattern_uv(ps, key, edges, side_t, inner)
            own = _spaced_template(key, local)[0]  # the strips: the triangles along the sides
        uvs.append(np.take_along_axis(local, own.reshape(len(ps), -1)[..., None], axis=1).reshape(-1, 3, 2))
        patches.append(np.repeat(ps, own.shape[1]))
    if not uvs:
        return np.zeros((0, 3, 3)), np.zeros((0, 3, 2)), np.zeros(0, np.int64)
    uv, patch = np.concatenate(uvs), np.concatenate(patches)
    collapsed = edges.collapsed[edges.edge[patch]]  # (R, 4) BOTTOM, RIGHT, TOP, LEFT
    u, v = uv[..., 0], uv[..., 1]
    on = np.stack([(v == 0) & collapsed[:, :1], (u == 1) & collapsed[:, 1:2], (v == 1) & collapsed[:, 2:3],
                   (u == 0) & collapsed[:, 3:]], axis=-1)  # (R, 3 corners, 4 sides)
    if patch_deviation_opencl.supports(runtime):
        corners = patch_deviation_opencl.points(runtime, h, uv.reshape(-1, 2), np.repeat(patch, 3)).reshape(-1, 3, 3)
    else:
        corners = evaluate(h[patch], uv[..., 0], uv[..., 1])
    at_pole = on.any(axis=2)
    if at_pole.any():  # the one point of the pole, as the mesh has it; two corners there: flattened, dropped
        side = on.argmax(axis=2)
        corners[at_pole] = edges.point[edges.edge[np.broadcast_to(patch[:, None], side.shape), side][at_pole]]
        same = [at_pole[:, a] & at_pole[:, b] & (corners[:, a] == corners[:, b]).all(axis=1)
                for a, b in ((0, 1), (1, 2), (0, 2))]
        keep = ~(same[0] | same[1] | same[2])
        corners, uv, patch = corners[keep], uv[keep], patch[keep]
        uv = _pole_corners(uv, edges.collapsed[edges.edge[patch]])
    as_stored = np.float32
    return corners.astype(as_stored).astype(np.float64), uv.astype(as_stored).astype(np.float64), patch


def inner_pairs(inner_levels, count):
    """Inner levels as (P, 2) int64 steps along u and along v: (P,) (the same both ways) or (P, 2) as given."""
    n = np.asarray(inner_levels, np.int64)
    n = np.stack([n, n], 1) if n.ndim == 1 else n
    if n.shape != (count, 2):
        raise InvalidInputError(f"Inner levels must be (P,) or (P, 2) for {count} patches; got {n.shape}")
    return np.maximum(n, 1)


def grid_deviation(control, inner_levels, spacing=None, points=_B, runtime=None):
    """The largest distance between the surface and the triangles of each patch's inner grid (the cells between
    its inner points (i / n, j / m), or where ``spacing`` (a `Spacing`) puts them, each cut along its
    (i, j)-(i+1, j+1) diagonal as the pattern cuts it), measured at `_B` (or the barycentric ``points`` given) in
    every triangle as `triangle_deviation` does, by tensor products (one per pair of inner levels; the groups, or
    halves of them, on worker threads: `kernels.common.workers`), or on ``runtime``'s OpenCL device where it has
    double precision (`patch_deviation_opencl`: the same points and parameters). Returns (P, 3) float64: the largest
    distance anywhere, at the cells' sides along u, and along v (0 for a patch with fewer than 2 cells a way)."""
    h = check_patches(control)
    n_in = inner_pairs(inner_levels, len(h))
    out = np.zeros((len(h), 3))
    ok = (n_in >= 3).all(axis=1)
    if patch_deviation_opencl.supports(runtime):
        ps = np.flatnonzero(ok)
        if spacing is None:
            tu, tv = (step_spacing.padded_params(np.array([[0.0, 1.0]]).repeat(len(ps), 0), n_in[ps, axis])
                      for axis in (0, 1))
        else:
            tu, tv = (step_spacing.padded_params(spacing.inner[ps, axis], n_in[ps, axis]) for axis in (0, 1))
        out[ps] = patch_deviation_opencl.grid_deviation(runtime, h[ps], n_in[ps], tu, tv, points)
        return out
    # equal steps: one group a pair of counts (the bases shared); spaced steps (each patch its own bases): counts
    # rounded up to a multiple of GRID_BUCKET, the cells past a patch's own count empty
    key = n_in if spacing is None else -(-n_in // GRID_BUCKET) * GRID_BUCKET
    pairs, pair_of = np.unique(key, axis=0, return_inverse=True)
    jobs = []
    for q, (nu, nv) in enumerate(pairs):
        ps = np.flatnonzero((pair_of.ravel() == q) & ok)
        if len(ps):  # a share for each thread, and at most GRID_CELLS cells a job (its arrays' memory)
            parts = max(min(len(ps), workers.WORKERS + 1), -(-len(ps) * int(nu) * int(nv) // GRID_CELLS))
            jobs += [(part, int(nu), int(nv)) for part in np.array_split(ps, min(parts, len(ps)))]
    if not jobs:
        return out

    def run(job):
        ps, nu, nv = job
        out[ps] = _grid_group(h[ps], nu, nv, None if spacing is None else spacing.of(ps), points, n_in[ps])

    if workers.in_worker():
        for job in jobs:
            run(job)
        return out
    with workers.parallel_section():
        done = [workers.submit(run, job) for job in jobs[1:]]
        run(jobs[0])
        for future in done:
            future.result()
    return out


def _grid_group(h, nu, nv, spacing, points, counts):
    """`grid_deviation` of nets h (p, k, k, 4) that all step nu along u and nv along v (equal steps), or whose own
    counts (p, 2) are at most that (spaced steps: their parameters past their own last inner point stay there, so
    the cells past it are empty): (p, 3)."""
    d = h.shape[1] - 1
    out = np.zeros((len(h), 3))
    tri_offsets = (np.array([[0, 0], [1, 0], [1, 1]], np.float64), np.array([[0, 0], [1, 1], [0, 1]], np.float64))
    # the cells' corners (the inner grid) and each sample point of every cell, by offsets a in each direction:
    # the v basis contracted once per distinct a along v, then the u basis per sample
    cu, cv = np.arange(1, nu - 1), np.arange(1, nv - 1)
    if spacing is None:
        tu, tv = (np.arange(nu + 1) / nu)[None], (np.arange(nv + 1) / nv)[None]

        def at(t, c, a, n):
            return (c + a) / n
    else:
        tu, tv = (_padded_inner(spacing.inner[:, axis], counts[:, axis], n) for axis, n in ((0, nu), (1, nv)))

        def at(t, c, a, n):
            return t[:, c] + a * (t[:, c + 1] - t[:, c])
    g = _grid_at(h, tu[:, 1:-1], tv[:, 1:-1])
    corners = g[:, :3] / g[:, 3:]  # (p, 3, nv - 1, nu - 1)
    # every sample's offsets in its cell are sixths: the bases at each, computed together
    sixths = np.arange(7) / 6
    b_u = bernstein(np.stack([at(tu, cu, a, nu) for a in sixths]), d)  # (7, [p,] U, k)
    b_v = bernstein(np.stack([at(tv, cv, a, nv) for a in sixths]), d)
    along_v = {}
    for offs in tri_offsets:
        c0, c1, c2 = (corners[:, :, int(dv):int(dv) + nv - 2, int(du):int(du) + nu - 2] for du, dv in offs)
        c1, c2 = c1 - c0, c2 - c0
        for bary in points:
            iu, iv = (round(float(x) * 6) for x in bary @ offs)
            if iv not in along_v:
                along_v[iv] = _contract_v_basis(h, b_v[iv])
            on = _contract_u_basis(along_v[iv], b_u[iu])  # (p, 4, V, U) homogeneous
            gap = on[:, :3] / on[:, 3:] - c0
            gap -= bary[1] * c1
            gap -= bary[2] * c2
            gap *= gap
            dev = np.sqrt((gap[:, 0] + gap[:, 1] + gap[:, 2]).reshape(len(h), -1).max(axis=1))
            a = bary @ offs
            out[:, 0] = np.maximum(out[:, 0], dev)
            if a[1] in (0.0, 1.0):  # on a side of the cell along u
                out[:, 1] = np.maximum(out[:, 1], dev)
            elif a[0] in (0.0, 1.0):  # along v
                out[:, 2] = np.maximum(out[:, 2], dev)
    return out


def _padded_inner(cum, counts, n):
    """Parameters (p, n + 1) of each table cum (p, M + 1) at its own count (p,) <= n, the values past its last
    inner point (counts - 1) held there."""
    t = step_spacing.padded_params(cum, counts)
    t = np.concatenate([t, np.ones((len(t), n + 1 - t.shape[1]))], axis=1) if t.shape[1] < n + 1 else t[:, :n + 1]
    last = counts - 1
    held = np.arange(n + 1)[None] > last[:, None]
    return np.where(held, t[np.arange(len(t)), last][:, None], t)


def _contract_v(h, tv):
    """Nets h (p, k, k, c) contracted with the v basis at tv (V,) shared, or (p, V) per net: (p, c, k, V), each
    coordinate a plane (what numpy's element-wise steps run fastest on)."""
    return _contract_v_basis(h, bernstein(tv, h.shape[1] - 1))


def _contract_u(along_v, tu):
    """`_contract_v`'s (p, c, k, V) contracted with the u basis at tu (U,) shared, or (p, U) per net: points
    (p, c, V, U), each coordinate a plane."""
    return _contract_u_basis(along_v, bernstein(tu, along_v.shape[2] - 1))


def _contract_v_basis(h, b):
    """`_contract_v` with given basis values b (V, k) shared or (p, V, k) per net (a derivative's too)."""
    bt = np.swapaxes(b, -1, -2)  # (k, V) or (p, k, V)
    return np.matmul(h.transpose(0, 3, 1, 2), bt if bt.ndim == 2 else bt[:, None])


def _contract_u_basis(along_v, b):
    """`_contract_u` with given basis values b (U, k) shared or (p, U, k) per net."""
    bt = np.swapaxes(b, -1, -2)
    return np.matmul(np.swapaxes(along_v, -1, -2), bt if bt.ndim == 2 else bt[:, None])


def _plane_points(planes):
    """Coordinate planes (p, c, V, U) as points (p, V U, c), row by row."""
    return planes.transpose(0, 2, 3, 1).reshape(len(planes), -1, planes.shape[1])


def _grid_at(h, tu, tv):
    """Homogeneous points (p, c, V, U) (coordinate planes) of nets h (p, k, k, c) at tu (1 or p, U) along u and
    tv (1 or p, V)."""
    return _contract_u(_contract_v(h, tv[0] if len(tv) == 1 else tv), tu[0] if len(tu) == 1 else tu)


def fitted_inner(grid_dev, inner_levels, tolerance, most):
    """Inner steps (P, 2) int64 in [1, most] from the inner grids' deviations measured at inner_levels (P, 2)
    (`grid_deviation`: anywhere, at the cells' sides along u, along v). Each patch's grid is modelled as straying
    A / n² + B / m² + C / nm at n steps along u and m along v (A and B from the cells' sides, C what their diagonals
    add); each patch gets the fewest cells n m that the model puts within FIT_AIM of the tolerance (every n tried,
    each with the fewest m: B x² + (C / n) x + A / n² - T <= 0 in x = 1 / m), or Max Level both ways where none is.
    A patch whose grid was not measured (fewer than 3 steps a way) keeps its levels."""
    g = np.asarray(grid_dev, np.float64)
    n = np.asarray(inner_levels, np.float64)
    aim = FIT_AIM * tolerance
    a, b = g[:, 1] * n[:, 0] ** 2, g[:, 2] * n[:, 1] ** 2
    c = np.maximum(g[:, 0] - g[:, 1] - g[:, 2], 0.0) * n[:, 0] * n[:, 1]
    small = 1e-3 * (a + b + c)
    a, b = np.maximum(a, small)[:, None], np.maximum(b, small)[:, None]
    c = c[:, None]
    measured = (n >= 3).all(axis=1) & (a[:, 0] + b[:, 0] + c[:, 0] > 0)
    u = np.arange(1, most + 1, dtype=np.float64)[None]  # (1, most): every count along u
    lin, rest = c / u, a / u ** 2 - aim
    root = np.sqrt(np.maximum(lin ** 2 - 4 * b * rest, 0.0))
    x = np.divide(-lin + root, 2 * b, out=np.zeros_like(root), where=b > 0)  # the largest 1 / v allowed
    ok = (rest < 0) & (x > 0)
    v = np.where(ok, np.maximum(1.0, np.ceil(np.divide(1.0, x, out=np.full_like(x, np.inf), where=ok) - 1e-9)),
                 np.inf)
    v = np.where(v <= most, v, np.inf)
    cells = u * v
    best = np.argmin(cells, axis=1)
    rows = np.arange(len(g))
    found = np.isfinite(cells[rows, best])
    fit = np.where(found[:, None], np.stack([u[0, best], v[rows, best]], axis=1), most).astype(np.int64)
    return np.where(measured[:, None], fit, np.asarray(inner_levels, np.int64))


def _sides_keep_up(edge_levels, inner, edges):
    """Edge levels raised to the steps of the patches beside them in the side's direction (a bottom or top side
    runs along u, a left or right one along v); a pole stays one segment."""
    el = np.asarray(edge_levels, np.int64).copy()
    np.maximum.at(el, edges.edge[:, [0, 2]].ravel(), np.repeat(inner[:, 0], 2))
    np.maximum.at(el, edges.edge[:, [1, 3]].ravel(), np.repeat(inner[:, 1], 2))
    return np.where(edges.collapsed, 1, el)


def estimate(edge_levels, inner_levels):
    """The mesh's size at these levels, before it is made: an `Estimate` (peak bytes: the arrays being built,
    float64, and the result)."""
    n = np.maximum(np.asarray(inner_levels, np.int64), 2)
    n = np.stack([n, n], 1) if n.ndim == 1 else n
    vertices = int(4 * len(n) + (np.asarray(edge_levels, np.int64) - 1).sum() + ((n - 1).prod(axis=1)).sum())
    triangles = int((2 * n.prod(axis=1)).sum())
    return Estimate(vertices, triangles, vertices * 200 + triangles * 160)


def tessellate(control, lod, camera=None, budget_bytes=None, backend="auto"):
    """Levels from ``lod`` and the welded mesh at them: a `Tessellation`. With TOLERANCE among the metrics, every
    triangle is measured against the surface (`triangle_deviation`) and each side
    (`kernels.common.rational_bezier.chord_deviation`), and the levels of what is over are raised, until all is
    within the tolerance or at Max Level; a patch still over it at Max Level is split in two along each direction at
    Max Level (`kernels.surfaces.patch_split`, with every patch that shares those sides) and the whole is made again,
    up to SPLIT_ROUNDS times. Every mesh is checked against ``budget_bytes`` (`kernels.common.budget.check_budget`)
    before it is made. backend: where the triangles are measured: "auto" (an OpenCL device with double precision
    where one is set up, else numpy), "numpy", or "opencl" (`patch_deviation_opencl`; an error without such a
    device)."""
    h = check_patches(control)
    runtime = _measuring_runtime(backend, h.shape[1])
    parent = np.arange(len(h))
    box = np.broadcast_to(np.array([[0.0, 1.0], [0.0, 1.0]]), (len(h), 2, 2))
    for attempt in range(SPLIT_ROUNDS + 1):
        result = _tessellate_once(h, lod, camera, budget_bytes, runtime)
        result.parent, result.box = parent, box
        if len(result.unmet) == 0 or attempt == SPLIT_ROUNDS:
            return result
        want = np.ones((len(h), 2), np.int64)
        at_top = result.inner_levels[result.unmet] >= lod.max_level
        at_top[~at_top.any(axis=1)] = True  # over at its sides only: split both ways
        want[result.unmet] = np.where(at_top, 2, 1)
        counts = patch_split.consistent_counts(want, result.edges.edge, result.edges.reversed)
        h, sub_parent, sub_box = patch_split.split_patches(h, counts, result.edges)
        lo, size = box[sub_parent, :, :1], box[sub_parent, :, 1:] - box[sub_parent, :, :1]
        parent, box = parent[sub_parent], lo + sub_box * size
    return result


def _measuring_runtime(backend, k):
    """The OpenCL runtime that measures for `tessellate`'s ``backend`` nets of k x k points, its program built, or
    None (numpy). With "auto", a device without double precision, or whose compiler refuses the program, leaves the
    measuring to numpy (the refusal logged once); with "opencl", either is an error."""
    runtime = backend_runtime(backend, "measuring Tessellate Surface's triangles")
    if runtime is None:
        return None
    if not patch_deviation_opencl.supports(runtime):
        if backend == "opencl":
            raise OpenCLUnavailableError(f"The OpenCL device {runtime.description} has no double precision, which "
                                         "measuring the triangles needs; use the numpy backend")
        return None
    try:
        patch_deviation_opencl.build(runtime, k)
    except TesseraError as err:
        if backend == "opencl":
            raise
        _log_once(f"Tessera: measuring Tessellate Surface's triangles with numpy: {err}")
        return None
    return runtime


@cache
def _log_once(message):
    logging.getLogger(__name__).warning(message)


def _tessellate_once(h, lod, camera, budget_bytes, runtime=None):
    """`tessellate` without splitting: a `Tessellation` of these patches (parent and box left to the caller)."""
    edges = patch_edges(h)
    spacing = patch_spacing(h, edges) if "TOLERANCE" in lod.metrics else None
    el, inner = patch_levels(h, edges, lod, camera, spacing)
    if "TOLERANCE" in lod.metrics:
        # the inner grids fitted to their measured deviation, before any mesh is made; then a side as fine as the
        # patches beside it: no stretched triangles along it
        others = tuple(m for m in lod.metrics if m != "TOLERANCE")
        floor = patch_levels(h, edges, replace(lod, metrics=others), camera)[1] if others else 1
        # the model from a coarse grid (it falls with the square of the steps): only the sides' and centroids'
        probe = np.full((len(h), 2), FIT_PROBE)
        first = grid_deviation(h, probe, spacing, points=_B[:4], runtime=runtime)
        inner = np.maximum(floor, fitted_inner(first, probe, lod.tolerance, lod.max_level))
        el = _sides_keep_up(el, inner, edges)
    lower = "a lower Max Level or a larger Tolerance" if "TOLERANCE" in lod.metrics else "a lower Max Level"
    if "TOLERANCE" in lod.metrics:
        el, inner, dev = _meet_tolerance(h, el, inner, edges, spacing, lod, budget_bytes, lower, runtime)
    check_budget(estimate(el, inner), budget_bytes, lower)
    mesh = tessellate_patches(h, el, inner, edges, spacing)
    if "TOLERANCE" not in lod.metrics:
        return Tessellation(mesh, el, inner, edges, np.full(len(h), np.nan), np.zeros(0, np.int64))
    return Tessellation(mesh, el, inner, edges, dev, np.flatnonzero(dev > lod.tolerance))


def stored_error(h):
    """How far storing a mesh of nets h (P, k, k, 4) in float32 can move a measured distance: a position's
    rounding (half a unit in the last place a coordinate, √3 of it a point) and its (u, v)'s, over the model's
    size: 4 · 2⁻²⁴ of it."""
    return 4.0 * 2.0 ** -24 * (float(np.abs(cartesian(h)).max()) + 1.0)


def _meet_tolerance(h, el, inner, edges, spacing, lod, budget_bytes, lower, runtime=None):
    """Levels raised until every triangle is within the tolerance, measured before any mesh is made: the inner
    grids by tensor products (`grid_deviation`), the triangles along the patches' sides one by one
    (`rim_triangles`), each side's chords; each round measures again only the patches and sides whose levels
    changed (on ``runtime``'s OpenCL device where given). The measures are float64 and the mesh is stored in
    float32: the levels aim under the tolerance by what storing it can move (`stored_error`). Returns (edge levels
    (E,), inner levels (P, 2), deviation (P,) measured at them)."""
    tol, top = lod.tolerance - stored_error(h), lod.max_level
    grid_dev = np.zeros((len(h), 3))
    side_dev = np.zeros(len(el))
    rim = [np.zeros((0, 3, 2)), np.zeros(0, np.int64), np.zeros(0)]  # (u, v), patch, deviation

    def measure(el, inner, changed, changed_sides):
        """Measure again what changed; the deviation of each patch (P,)."""
        ps = np.flatnonzero(changed)
        if len(ps):
            grid_dev[ps] = grid_deviation(h[ps], inner[ps], None if spacing is None else spacing.of(ps),
                                          runtime=runtime)
            corners, uv, patch = rim_triangles(h, el, inner, edges, spacing, ps, runtime)
            keep = ~changed[rim[1]]
            rim[:] = (np.concatenate([rim[0][keep], uv]), np.concatenate([rim[1][keep], patch]),
                      np.concatenate([rim[2][keep], _deviation(h, corners, uv, patch, runtime)]))
        es = np.flatnonzero(changed_sides)
        side_dev[es] = chord_deviation(edges.control[es], el[es], None if spacing is None else spacing.edge[es])
        dev = grid_dev[:, 0].copy()
        np.maximum.at(dev, rim[1], rim[2])
        return dev

    changed, changed_sides = np.ones(len(h), bool), np.ones(len(el), bool)
    for _round in range(TOLERANCE_ROUNDS):
        check_budget(estimate(el, inner), budget_bytes, lower)
        dev = measure(el, inner, changed, changed_sides)
        rim_uv, rim_patch, rim_dev = rim
        # a triangle over the tolerance with a corner on a side of its patch that has fewer segments than the
        # inside has along it raises that side (its long edge lies along it)
        over = rim_dev > tol
        uv, tp, td = rim_uv[over], rim_patch[over], rim_dev[over]
        on_side = np.stack([(uv[..., 1] == 0).any(1), (uv[..., 0] == 1).any(1), (uv[..., 1] == 1).any(1),
                            (uv[..., 0] == 0).any(1)], 1)  # BOTTOM, RIGHT, TOP, LEFT
        side_need = side_dev.copy()
        side_need[edges.collapsed] = 0.0  # a pole has no length to split
        # a triangle over the tolerance along a side with more segments than the inside has along it (a finer
        # patch beside it): the inside takes the side's count that way, so the strip between them is regular
        coarse_side, fine_side = np.zeros(len(tp), bool), np.zeros(len(tp), bool)
        new_inner = inner.copy()
        for side in range(4):
            e = edges.edge[tp, side]
            along = inner[tp, side % 2]
            use = on_side[:, side] & (el[e] < along) & ~edges.collapsed[e]
            np.maximum.at(side_need, e[use], td[use])
            finer = on_side[:, side] & (el[e] > along) & ~edges.collapsed[e] & ~use
            np.maximum.at(new_inner[:, side % 2], tp[finer], el[e[finer]])
            coarse_side |= use
            fine_side |= finer
        new_el = np.where(side_need > tol, np.maximum(el + 1, steps_for(side_need, el, tol, top)), el)
        # a grid over the tolerance: refitted (`fitted_inner`), at least one step more; any other triangle along
        # a side: both directions
        rim_need = np.zeros(len(h))
        other = ~coarse_side & ~fine_side
        np.maximum.at(rim_need, tp[other], td[other])
        grid_over = grid_dev[:, 0] > tol
        refit = np.maximum(new_inner, fitted_inner(grid_dev, inner, tol, top))
        new_inner[grid_over] = refit[grid_over]
        stuck = grid_over & (new_inner == inner).all(axis=1)
        new_inner[stuck] += 1
        # a triangle along a side over it: the grid's model scaled up to what was measured there, refitted (the
        # directions keep the grid's best ratio), at least one step more the way that strays most
        rim_over = np.flatnonzero(rim_need > tol)
        if len(rim_over):
            scaled = grid_dev[rim_over] * (rim_need[rim_over] / np.maximum(grid_dev[rim_over, 0], 1e-300))[:, None]
            unmeasured = grid_dev[rim_over, 0] <= 0
            scaled[unmeasured] = rim_need[rim_over][unmeasured, None] * [1.0, 0.5, 0.5]
            want = np.maximum(new_inner[rim_over], fitted_inner(scaled, inner[rim_over], tol, top))
            # no step more from the model: one more the way that strays most (unmeasured: the way with fewer
            # steps), or the other way where that one is at Max Level
            same = (want <= inner[rim_over]).all(axis=1)
            was = inner[rim_over]
            axis = np.where(unmeasured, was[:, 1] < was[:, 0], scaled[:, 2] > scaled[:, 1]).astype(np.int64)
            axis = np.where(was[np.arange(len(axis)), axis] >= top, 1 - axis, axis)
            want[same, axis[same]] = was[same, axis[same]] + 1
            new_inner[rim_over] = want
        new_inner = np.minimum(new_inner, top)
        new_el = np.minimum(_sides_keep_up(new_el, new_inner, edges), top)
        changed_sides = new_el != el
        changed = (new_inner != inner).any(axis=1) | changed_sides[edges.edge].any(axis=1)
        if not changed.any():
            return el, inner, dev
        el, inner = new_el, new_inner
    check_budget(estimate(el, inner), budget_bytes, lower)
    return el, inner, measure(el, inner, changed, changed_sides)


def tessellate_patches(control, edge_levels, inner_levels, edges=None, spacing=None):
    """The welded triangle mesh of the patches at these levels: a `PatchMesh`; equal steps, or steps where
    ``spacing`` (a `Spacing`) puts them (then each strip between a side and the inner grid is zipped by the points'
    parameters)."""
    h = check_patches(control)
    edges = edges if edges is not None and edges.collapsed is not None else patch_edges(h)
    k = h.shape[1]
    deg = k - 1
    n_p = len(h)
    el = np.asarray(edge_levels, np.int64)
    # vertices: corners (4 per patch, merged below), edge interior points (canonical order), inner grids
    corners = cartesian(h[:, [0, deg, deg, 0], [0, 0, deg, deg]])  # (P, 4, 3): (0,0) (1,0) (1,1) (0,1)
    # a corner on a collapsed side is that side's point (the poles of all patches around it are one point)
    side_corners = ((0, 1), (1, 2), (3, 2), (0, 3))  # BOTTOM, RIGHT, TOP, LEFT: their corners in side direction
    for side, (a, b) in enumerate(side_corners):
        col = edges.collapsed[edges.edge[:, side]]
        corners[col, a] = edges.point[edges.edge[col, side]]
        corners[col, b] = edges.point[edges.edge[col, side]]
    corner_uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float64)
    counts = el - 1
    e_first = np.concatenate([[0], np.cumsum(counts)])[:-1]
    e_of = np.repeat(np.arange(len(el)), counts)
    kk = np.arange(len(e_of)) - e_first[e_of] + 1
    side_t = None if spacing is None else spacing.side_params(el)  # (E, max level + 1)
    t = kk / el[e_of] if spacing is None else side_t[e_of, kk]
    b = bernstein(t, deg)
    edge_pts = cartesian(np.matmul(b[:, None], edges.control[e_of])[:, 0])
    edge_pts[edges.collapsed[e_of]] = edges.point[e_of[edges.collapsed[e_of]]]  # exactly the one point
    # each edge's (patch, uv) for the vertex record: the first patch side that uses it
    sides = np.arange(n_p * 4)
    first_side = np.full(len(el), len(sides), np.int64)
    np.minimum.at(first_side, edges.edge.ravel(), sides)
    fp, fs = first_side // 4, first_side % 4
    fr = edges.reversed.ravel()[first_side]
    tl = np.where(fr[e_of], 1.0 - t, t)
    side_uv = np.stack([np.select([fs[e_of] == 1, fs[e_of] == 3], [1.0, 0.0], tl),
                        np.select([fs[e_of] == 0, fs[e_of] == 2], [0.0, 1.0], tl)], 1)
    side_counts = el[edges.edge]  # (P, 4)
    n_in = _pattern_counts(inner_pairs(inner_levels, n_p), side_counts)  # (P, 2): steps along u and along v
    mu, mv = n_in[:, 0] - 1, n_in[:, 1] - 1
    count = mu * mv
    in_first = np.concatenate([[0], np.cumsum(count)])[:-1]
    inner_pts = np.empty((int(count.sum()), 3))
    inner_uv = np.empty((len(inner_pts), 2))
    inner_nrm = np.empty((len(inner_pts), 3))
    p_of = np.repeat(np.arange(n_p), count)
    pairs, pair_of = np.unique(n_in, axis=0, return_inverse=True)
    for q, (nu, nv) in enumerate(pairs):  # one tensor product per pair of inner counts: rows j, columns i
        ps = np.flatnonzero((pair_of.ravel() == q) & (count > 0))
        if len(ps) == 0:
            continue
        if spacing is None:  # the bases shared by the group
            t_u, t_v = (np.arange(1, nu) / nu)[None], (np.arange(1, nv) / nv)[None]
            at_u, at_v = t_u[0], t_v[0]
        else:  # each patch its own
            t_u, t_v = spacing.inner_params(ps, 0, nu)[:, 1:-1], spacing.inner_params(ps, 1, nv)[:, 1:-1]
            at_u, at_v = t_u, t_v
        along_v = _contract_v(h[ps], at_v)
        along_dv = _contract_v_basis(h[ps], bernstein_derivative(at_v, deg))
        grid = _contract_u(along_v, at_u)  # coordinate planes (p, 4, V, U), and the derivatives'
        g_u = _contract_u_basis(along_v, bernstein_derivative(at_u, deg))
        g_v = _contract_u(along_dv, at_u)
        rows = in_first[ps][:, None] + np.arange((nu - 1) * (nv - 1))[None]
        w = grid[:, 3:]
        pts = grid[:, :3] / w
        inner_pts[rows] = _plane_points(pts)
        # the normal dS/du x dS/dv (up to w², which the division puts back), plane by plane
        a, b = g_u[:, :3] - pts * g_u[:, 3:], g_v[:, :3] - pts * g_v[:, 3:]
        w2 = w[:, 0] * w[:, 0]
        cross = np.stack([a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1], a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
                          a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]], axis=1)
        inner_nrm[rows] = _plane_points(cross / w2[:, None])
        jj, ii = np.divmod(np.arange((nu - 1) * (nv - 1)), nu - 1)
        inner_uv[rows] = np.stack(np.broadcast_arrays(t_u[:, ii], t_v[:, jj]), -1)

    n_c = 4 * n_p
    base_e, base_i = n_c, n_c + len(edge_pts)
    positions = np.concatenate([corners.reshape(-1, 3), edge_pts, inner_pts])
    uv = np.concatenate([np.tile(corner_uv, (n_p, 1)), side_uv, inner_uv])
    patch = np.concatenate([np.repeat(np.arange(n_p), 4), fp[e_of], p_of])

    tris, tri_patch, strip_uv = [], [], []  # the strips' corner (u, v); the cells' are their inner points'
    keys = np.concatenate([side_counts, n_in], axis=1)
    classes, inverse = np.unique(keys, axis=0, return_inverse=True)
    for cls, key in enumerate(classes):
        ps = np.flatnonzero(inverse.ravel() == cls)
        tmpl = pattern(*(int(x) for x in key))
        cols = [4 * ps[:, None] + np.arange(4)[None]]
        for side in range(4):
            e, r = edges.edge[ps, side], edges.reversed[ps, side]
            q = np.arange(int(key[side]) - 1)[None]  # the side's interior points in the patch's direction
            cols.append(base_e + e_first[e][:, None] + np.where(r[:, None], q.shape[1] - 1 - q, q))
        cells = (int(key[4]) - 1) * (int(key[5]) - 1) if key[4] > 1 and key[5] > 1 else 0
        cols.append(base_i + in_first[ps][:, None] + np.arange(cells)[None])
        lmap = np.concatenate(cols, 1)
        tri_patch.append(np.repeat(ps, len(tmpl)))
        if spacing is None:
            tris.append(lmap[:, tmpl].reshape(-1, 3))
            on_rim = tmpl[(tmpl < sum(int(c) for c in key[:4])).any(axis=1)]  # a corner or a side's point in it
            strip_uv.append(np.broadcast_to(_pattern_uv(tuple(int(x) for x in key))[on_rim],
                                            (len(ps),) + on_rim.shape + (2,)).reshape(-1, 3, 2))
        else:
            local_uv = _spaced_pattern_uv(ps, key, edges, side_t, inner_uv[cols[-1] - base_i])
            strip, cells = _spaced_template(key, local_uv)
            own = strip.reshape(len(ps), -1)  # (p, 3S)
            tris.append(np.concatenate([np.take_along_axis(lmap, own, axis=1).reshape(len(ps), -1, 3),
                                        lmap[:, cells]], axis=1).reshape(-1, 3))
            strip_uv.append(np.take_along_axis(local_uv, own[..., None], axis=1).reshape(-1, 3, 2))
    tris, tri_patch, strip_uv = np.concatenate(tris), np.concatenate(tri_patch), np.concatenate(strip_uv)
    # a cell's corners are all inner points (a strip's triangle has a corner or a side's point), which are never
    # merged: its corners' (u, v) are theirs, taken once the triangles are known
    is_cell = (tris >= base_i).all(axis=1)
    # corners shared by patches, and points of collapsed sides, are the same point: merge exactly equal positions
    # of corners and side points (inner points are never merged)
    shared = n_c + len(edge_pts)
    _, first, inv = np.unique(positions[:shared], axis=0, return_index=True, return_inverse=True)
    remap = np.concatenate([first[inv.ravel()], np.arange(shared, len(positions))])
    merged = remap[tris]
    keep = (merged[:, 0] != merged[:, 1]) & (merged[:, 1] != merged[:, 2]) & (merged[:, 0] != merged[:, 2])
    strip_uv = strip_uv[keep[~is_cell]]  # only strips flatten (at a pole)
    if edges.collapsed.any():  # only the strips' triangles with a corner on a pole move
        strip_patch = tri_patch[~is_cell & keep]
        near = np.flatnonzero(edges.collapsed[edges.edge].any(axis=1)[strip_patch]
                              & (((strip_uv == 0) | (strip_uv == 1)).any(axis=(1, 2))))
        strip_uv[near] = _pole_corners(strip_uv[near], edges.collapsed[edges.edge[strip_patch[near]]])
    uv32 = uv.astype(np.float32)
    tri_uv = uv32[tris[keep][:, ::-1]]  # reversed, as the triangles are below; the strips' then set
    tri_uv[np.flatnonzero(~is_cell[keep])] = strip_uv[:, ::-1]
    tris, tri_patch = merged[keep], tri_patch[keep]
    used = np.zeros(len(positions), bool)
    used[tris.ravel()] = True
    new_id = np.cumsum(used) - 1
    # normals from the surface (corners and sides from their first patch, a vanishing one a little inside it); a
    # merged vertex (a pole) gets the mean of its patches' normals there
    _, normals = _point_and_normal(h[patch[:shared]], uv[:shared, 0], uv[:shared, 1])
    length = np.linalg.norm(inner_nrm, axis=1)
    weak = np.flatnonzero(length <= 1e-12 * (1.0 + np.abs(corners).max()) ** 2)
    if len(weak):
        inner_nrm[weak] = _point_and_normal(h[p_of[weak]], inner_uv[weak, 0], inner_uv[weak, 1])[1]
        length[weak] = 1.0
    summed = np.zeros_like(normals)  # inner points are never merged: only the shared ones are summed
    np.add.at(summed, remap[:shared], normals)
    length_s = np.linalg.norm(summed, axis=1, keepdims=True)
    normals = np.where(length_s > 0, summed / np.where(length_s > 0, length_s, 1.0), normals)
    normals = np.concatenate([normals, inner_nrm / np.where(length > 0, length, 1.0)[:, None]])
    # Blender's orientation: the pattern's counter-clockwise (u, v) triangles reversed, the normals along dS/dv x dS/du
    return PatchMesh(positions[used].astype(np.float32), new_id[tris[:, ::-1]].astype(np.int32),
                     uv32[used], patch[used], tri_patch, tri_uv,
                     -normals[used].astype(np.float32))


def _spaced_template(key, local_uv):
    """The triangles of the pattern of class key, for patches whose points lie at local_uv (p, L, 2) (spaced
    steps), in local indices: (strips (p, S, 3), each patch's own: each strip zipped by the points' parameters
    (`kernels.common.quad_pattern.zip_by_params`), so a side finer than the grid beside it meets it without skew;
    cells (C, 3), the inner grid's as `pattern` makes them, the same for all). A strip tile (an inner count of 1)
    is all strip."""
    key_t = tuple(int(x) for x in key)
    tmpl = pattern(*key_t)
    if key_t[4] < 2 or key_t[5] < 2:  # a strip tile: no ring to meet
        return np.broadcast_to(tmpl, (len(local_uv),) + tmpl.shape), tmpl[:0]
    rows, ring, _ = strips(*key_t)
    parts, n_strip = [], 0
    for side in range(4):
        t_row, t_ring = local_uv[:, rows[side], side % 2], local_uv[:, ring[side], side % 2]
        if side >= 2:  # TOP and LEFT run against u and v
            t_row, t_ring = 1.0 - t_row, 1.0 - t_ring
        parts.append(zip_by_params(rows[side], ring[side], t_row, t_ring))
        n_strip += len(rows[side]) + len(ring[side]) - 2
    return np.concatenate(parts, axis=1), tmpl[n_strip:]


def _pattern_counts(n_in, side_counts):
    """The inner steps (P, 2) the pattern is made with: as terrain tiles, one step along u is a strip between the
    left and right sides when the bottom and top are one segment each (and along v likewise); else at least 2."""
    one = side_counts == 1
    return np.stack([np.where((n_in[:, 0] == 1) & ~(one[:, 0] & one[:, 2]), 2, n_in[:, 0]),
                     np.where((n_in[:, 1] == 1) & ~(one[:, 1] & one[:, 3]), 2, n_in[:, 1])], 1)


def _spaced_pattern_uv(ps, key, edges, side_t, inner):
    """(u, v) (p, L, 2) of each local vertex of the pattern of class key for patches ps (p,) whose steps are
    spaced: corners, each side's points at its edge's parameters (side_t (E, ·), canonical direction) read in the
    patch's direction, and the inner points' (u, v) inner (p, (n - 1)(m - 1), 2)."""
    counts = [int(c) for c in key[:4]]
    out = np.empty((len(ps), sum(counts) + inner.shape[1], 2))
    out[:, :4] = [[0, 0], [1, 0], [1, 1], [0, 1]]
    start = 4
    for side, c in enumerate(counts):
        e, r = edges.edge[ps, side], edges.reversed[ps, side]
        q = np.arange(1, c)[None]
        t = side_t[e[:, None], np.where(r[:, None], c - q, q)]
        along, fixed = (0, 1) if side in (0, 2) else (1, 0)  # BOTTOM, TOP run along u; RIGHT, LEFT along v
        out[:, start:start + c - 1, along] = np.where(r[:, None], 1.0 - t, t)
        out[:, start:start + c - 1, fixed] = 1.0 if side in (1, 2) else 0.0
        start += c - 1
    out[:, start:] = inner
    return out


def _pole_corners(tri_uv, collapsed):
    """Corner (u, v) of the triangles that meet at a pole: a corner on a side of its patch that is one point takes,
    along that side, the mean of the triangle's other two corners (as a UV sphere's poles do), so each triangle of a
    fan maps to the thin part of the surface it covers. tri_uv (T, 3, 2); collapsed (T, 4) its patch's sides BOTTOM,
    RIGHT, TOP, LEFT are one point."""
    uv = tri_uv.copy()
    u, v = tri_uv[..., 0], tri_uv[..., 1]
    others_u = (u.sum(axis=1, keepdims=True) - u) / 2
    others_v = (v.sum(axis=1, keepdims=True) - v) / 2
    on_uv = ((u == 1) & collapsed[:, 1:2]) | ((u == 0) & collapsed[:, 3:4])  # RIGHT, LEFT: v runs along them
    on_vv = ((v == 0) & collapsed[:, 0:1]) | ((v == 1) & collapsed[:, 2:3])  # BOTTOM, TOP: u runs along them
    uv[..., 1] = np.where(on_uv & ~on_vv, others_v, v)
    uv[..., 0] = np.where(on_vv & ~on_uv, others_u, u)
    return uv


@lru_cache(maxsize=4096)
def _pattern_uv(key):
    """(u, v) of each local vertex of the pattern of class key (c0, c1, c2, c3, n, m), from its `pattern_codes`:
    corners, side points k / c in each side's direction, inner (i / n, j / m)."""
    codes = pattern_codes(*key)
    kind, a, b = codes[:, 0].astype(int), codes[:, 1].astype(np.float64), codes[:, 2].astype(np.float64)
    c = np.asarray(key[:4], np.float64)
    n, m = float(key[4]), float(key[5])
    t = np.divide(a, c[np.clip(kind - 1, 0, 3)])
    u = np.select([kind == 0, kind == 1, kind == 2, kind == 3, kind == 4], [a, t, 1.0, t, 0.0], a / n)
    v = np.select([kind == 0, kind == 1, kind == 2, kind == 3, kind == 4], [b, 0.0, t, 1.0, t], b / m)
    return np.stack([u, v], 1)

"""Loop subdivision in the factored form ([Concheiro et al.]): the numpy reference, float64 inside, float32 out.

Each level is linear subdivision -> averaging -> correction factor (`loop_rules`), applied to vertex data of any
width (positions and point attributes side by side), with OpenSubdiv's boundary and crease rules. Every
vertex is computed once per level from its 1-ring, with sums in a fixed order (edge order), so results do not
depend on anything but the mesh. Corner data (UV maps, corner colours) is subdivided on its own face-varying
mesh with linear boundaries: seams and mesh borders stay where they are, like OpenSubdiv's
FVAR_LINEAR_BOUNDARIES and Blender's "UV Smooth: Keep Boundaries".

Faces of level L are numbered ``4^L * coarse + path``: the base-4 digits of ``path`` are the T/L/C/R slots
taken from the coarse triangle down (`loop_topology`), so a face's coarse triangle is ``face // 4^L``.
"""

from dataclasses import dataclass, field

import numpy as np

from ..common.budget import Estimate, check_budget
from ..common.errors import InvalidInputError
from ..common.opencl_runtime import backend_runtime
from ..common.topology import validate_triangles
from . import loop_opencl
from .loop_rules import (
    RULE_CORNER,
    RULE_CREASE,
    RULE_SMOOTH,
    child_sharpness,
    correction_factor,
    correction_table,
    vertex_rule,
)
from .loop_topology import coarse_level, level_counts, refine_level

MAX_LEVELS = 6
BOUNDARY_RULES = ("EDGE_ONLY", "EDGE_AND_CORNER")
#: Bytes per output vertex, triangle and channel the estimate counts (float64 work arrays, int64 topology).
BYTES_PER_VERTEX, BYTES_PER_TRIANGLE, BYTES_PER_CHANNEL = 8 * 3 * 3, 8 * 3 * 4, 8 * 3
BLOCK = 1 << 14  # rows per block of the edge rule
OPENCL_MIN_TRIANGLES = 4096  # output triangles from which "auto" takes OpenCL (faster from there: bench/loop.py)


@dataclass
class LoopResult:
    """A subdivided mesh.

    positions: (V, 3) float32; triangles: (F, 3) int32; edges: (E, 2) int32 and corner_edges: (F, 3) int32
    (edge of each local edge ``k`` -> ``k + 1``), known without a search; edge_sharpness: (E,) float32 what is
    left of each crease (boundaries infinite); point_attributes: name -> (V, ...) float32;
    corner_attributes: name -> (F, 3, ...) float32; levels: int; coarse_edges: (E0, 2) int32 the input's edges
    (level 0; edge ``j`` of the result lies on coarse edge ``j >> levels`` when ``j < E0 << levels``).
    """

    positions: np.ndarray
    triangles: np.ndarray
    edges: np.ndarray
    corner_edges: np.ndarray
    edge_sharpness: np.ndarray
    point_attributes: dict = field(default_factory=dict)
    corner_attributes: dict = field(default_factory=dict)
    levels: int = 0
    coarse_edges: np.ndarray | None = None

    def coarse_face(self):
        """(F,) int64: the coarse triangle each output face comes from."""
        return np.arange(len(self.triangles), dtype=np.int64) >> (2 * self.levels)

    def coarse_edge(self):
        """(E,) int64: the coarse edge each output edge lies on, -1 for edges inside coarse triangles."""
        j = np.arange(len(self.edges), dtype=np.int64)
        return np.where(j < (len(self.coarse_edges) << self.levels), j >> self.levels, -1)

    def edge_values(self, pairs, values, fill=0):
        """Per output edge (E,), the value given for the coarse edge it lies on: pairs (K, 2) int vertex ids of
        input edges (either order) with values (K,); ``fill`` elsewhere (pairs that are no edge are ignored)."""
        values = np.asarray(values)
        out = np.full(len(self.edges), fill, dtype=values.dtype)
        if len(pairs) == 0:
            return out
        n = int(self.coarse_edges.max(initial=0)) + 1
        keys = self.coarse_edges[:, 0].astype(np.int64) * n + self.coarse_edges[:, 1]
        pairs = np.asarray(pairs, np.int64).reshape(-1, 2)
        ok = pairs.max(axis=1) < n
        want = pairs[ok].min(axis=1) * n + pairs[ok].max(axis=1)
        at = np.minimum(np.searchsorted(keys, want), len(keys) - 1)
        per_coarse = np.full(len(keys), fill, dtype=values.dtype)
        hit = keys[at] == want
        per_coarse[at[hit]] = values[ok][hit]
        coarse = self.coarse_edge()
        inside = coarse >= 0
        out[inside] = per_coarse[coarse[inside]]
        return out


def estimate(n_vertices, n_edges, n_faces, levels, channels=0, corner_channels=0):
    """Output size and a working-memory estimate of ``levels`` Loop steps; channels: point-data floats beyond
    the position, corner_channels: floats per corner of all corner attributes together."""
    v, e, f = level_counts(n_vertices, n_edges, n_faces, levels)
    size = v * (BYTES_PER_VERTEX + 8 * channels) + e * 8 * 8 + f * (BYTES_PER_TRIANGLE + 8 * 3 * corner_channels)
    return Estimate(vertices=int(v), triangles=int(f), bytes=int(size))


def _vertex_sums(lv, values, mask=None):
    """Sum over each vertex's incident edges of ``values`` (E, D), in edge order; mask (E,) bool or None."""
    e0, e1 = lv.edges[:, 0], lv.edges[:, 1]
    n_v, d = lv.n_vertices, values.shape[1]
    out = np.empty((n_v, d))
    for j in range(d):
        w = values[:, j] if mask is None else np.where(mask, values[:, j], 0.0)
        out[:, j] = np.bincount(e0, w, n_v) + np.bincount(e1, w, n_v)
    return out


def _rule_values(lv, values, lin, rule, sharp_mask, smooth):
    """Vertex-vertex results for per-vertex rules: smooth (given), crease ``1/2 v + 1/4 (m1 + m2)`` over the
    two edges in ``sharp_mask``, corner ``v``."""
    out = np.where((rule == RULE_SMOOTH)[:, None], smooth, values)
    crease = rule == RULE_CREASE
    if crease.any():
        sums = _vertex_sums(lv, lin, sharp_mask)
        out[crease] = 0.5 * values[crease] + 0.25 * sums[crease]
    return out


def _even(lv, values, lin, cf):
    """New positions of the level's own vertices (V, D) from the linear midpoints ``lin`` (E, D)."""
    n = lv.valence
    e0, e1 = lv.edges[:, 0], lv.edges[:, 1]
    safe_n = np.maximum(n, 1)
    averaged = 0.25 * values + (0.75 / safe_n)[:, None] * _vertex_sums(lv, lin)  # averaging
    smooth = values + cf[n][:, None] * (averaged - values)  # correction factor
    s_parent = lv.edge_sharpness
    sharp_p = s_parent > 0
    if not sharp_p.any() and not lv.vertex_sharpness.any():  # no crease, corner or boundary: all smooth
        return np.where((n == 0)[:, None], values, smooth)
    count_p = np.bincount(e0, sharp_p, lv.n_vertices) + np.bincount(e1, sharp_p, lv.n_vertices)
    rule_p = vertex_rule(lv.vertex_sharpness, count_p)
    rule_p[n == 0] = RULE_CORNER
    out = _rule_values(lv, values, lin, rule_p, sharp_p, smooth)

    s_child = child_sharpness(s_parent)
    vs_child = child_sharpness(lv.vertex_sharpness)
    sharp_c = s_child > 0
    count_c = np.bincount(e0, sharp_c, lv.n_vertices) + np.bincount(e1, sharp_c, lv.n_vertices)
    rule_c = vertex_rule(vs_child, count_c)
    rule_c[n == 0] = RULE_CORNER
    blend = (rule_p != RULE_SMOOTH) & (rule_c != rule_p)
    if blend.any():  # a semi-sharp crease or corner fades: OpenSubdiv's fractional weight
        child = _rule_values(lv, values, lin, rule_c, sharp_c, smooth)
        fading = sharp_p & ~sharp_c
        s_fade = np.where(fading, s_parent, 0.0).astype(np.float64)
        total = np.bincount(e0, s_fade, lv.n_vertices) + np.bincount(e1, s_fade, lv.n_vertices)
        count = np.bincount(e0, fading, lv.n_vertices) + np.bincount(e1, fading, lv.n_vertices)
        v_fade = (lv.vertex_sharpness > 0) & (vs_child <= 0)
        total = total + np.where(v_fade, lv.vertex_sharpness, 0.0)
        count = count + v_fade
        # in float32, as OpenSubdiv computes it (sharpness is float)
        w = np.minimum(total.astype(np.float32) / np.maximum(count, 1).astype(np.float32), np.float32(1.0))
        w = w.astype(np.float64)[blend, None]
        out[blend] = (1.0 - w) * child[blend] + w * out[blend]
    return out


def _odd(lv, values, lin):
    """New vertices on the level's edges (E, D): smooth edges by averaging over the 6 neighbours of the linear
    midpoint (a, b and the midpoints of the 4 other edges of the two faces) and cf(6); sharp ones stay at the
    midpoint; semi-sharp ones (0 < s < 1) blend the two."""
    inner = ~lv.boundary
    opp = lv.opposite()
    opp.sort(axis=1)  # the two opposite vertices by id: the same sums whichever face comes first
    cf6 = correction_factor(6)
    smooth = np.empty_like(lin)
    for lo in range(0, len(lin), BLOCK):  # blocks keep the temporaries in cache
        hi = min(lo + BLOCK, len(lin))
        pa, pb = values[lv.edges[lo:hi, 0]], values[lv.edges[lo:hi, 1]]
        ring = pa + pb
        for c in (values[opp[lo:hi, 0]], values[opp[lo:hi, 1]]):
            ring += 0.5 * (pa + c) + 0.5 * (pb + c)  # the linear midpoints of the other edges of the two faces
        m = lin[lo:hi]
        smooth[lo:hi] = m + cf6 * ((0.25 * m + (0.75 / 6.0) * ring) - m)  # averaging, correction factor
    s = lv.edge_sharpness.astype(np.float64)
    out = np.where((s >= 1.0)[:, None] | ~inner[:, None], lin, smooth)
    semi = inner & (s > 0) & (s < 1)
    if semi.any():
        w = s[semi, None]
        out[semi] = w * lin[semi] + (1.0 - w) * smooth[semi]
    return out


def loop_step(lv, values, cf):
    """One Loop level of vertex data: values (V, D) float64 -> (V + E, D) float64 (old vertices, then one per
    edge). cf: `correction_table` covering the level's valences."""
    lin = 0.5 * (values[lv.edges[:, 0]] + values[lv.edges[:, 1]])  # linear subdivision
    return np.concatenate([_even(lv, values, lin, cf), _odd(lv, values, lin)])


def _face_varying(triangles, corner_values):
    """Weld corner values (T, 3, W) per vertex: fvar values (N, W) float64 and fvar triangles (T, 3) int64."""
    t = len(triangles)
    flat = np.asarray(corner_values, np.float64).reshape(t * 3, -1)
    rows = np.concatenate([np.asarray(triangles, np.float64).reshape(-1, 1), flat + 0.0], axis=1)  # -0.0 -> 0.0
    uniq, inverse = np.unique(rows, axis=0, return_inverse=True)
    return uniq[:, 1:], inverse.reshape(t, 3).astype(np.int64)


def _fvar_coarse(geo, fvar_tris, n_fvar):
    """The level-0 face-varying mesh: geometric creases and vertex sharpness carried over, every seam or border
    edge sharp and every value on one a corner (linear boundaries)."""
    lv = coarse_level(fvar_tris, n_fvar)
    lv.edge_sharpness[lv.face_edges.ravel()] = geo.edge_sharpness[geo.face_edges.ravel()]
    lv.edge_sharpness[lv.boundary] = 10.0
    vs = np.zeros(n_fvar, np.float32)
    vs[fvar_tris.ravel()] = geo.vertex_sharpness[geo.triangles.ravel()]
    vs[lv.edges[lv.boundary].ravel()] = 10.0
    lv.vertex_sharpness = vs
    return lv


@dataclass
class _Final:
    """The last level's topology (what `LoopResult` keeps)."""

    triangles: np.ndarray
    edges: np.ndarray
    face_edges: np.ndarray
    edge_sharpness: np.ndarray


def _runtime(backend, lv, est):
    """The OpenCL runtime to subdivide ``lv`` with, or None for numpy ("auto": OpenCL from
    OPENCL_MIN_TRIANGLES output triangles on, where it is faster)."""
    runtime = backend_runtime(backend, "Loop subdivision")
    if runtime is None:
        return None
    if not loop_opencl.supports(runtime, lv):
        if backend == "opencl":
            raise InvalidInputError("The OpenCL path subdivides infinitely sharp creases only (and needs a device "
                                    "with double precision); use the numpy backend for semi-sharp creases")
        return None
    if backend == "auto" and est.triangles < OPENCL_MIN_TRIANGLES:
        return None
    return runtime


def _levels(lv, values, levels, runtime, progress):
    """``levels`` Loop steps of vertex data (V, D) float64 on `LoopLevel` ``lv``: (values, last level)."""
    if levels == 0:
        return values, lv
    if runtime is not None and loop_opencl.supports(runtime, lv):
        values, tris, edges, face_edges, sharp = loop_opencl.subdivide(runtime, lv, values, levels, progress)
        return values, _Final(tris, edges, face_edges, sharp)
    for step in range(levels):
        values = loop_step(lv, values, correction_table(lv.valence.max(initial=6)))
        lv = refine_level(lv, final=step == levels - 1)
        if progress is not None:
            progress(step + 1, levels)
    return values, lv


def loop_subdivide(positions, triangles, levels, creases=None, vertex_sharpness=None, boundary="EDGE_ONLY",
                   point_data=None, corner_data=None, budget_bytes=0, progress=None, dtype=np.float32,
                   backend="auto"):
    """Subdivide a triangle mesh ``levels`` times with Loop's scheme.

    positions: (V, 3) float; triangles: (F, 3) int; levels: 0..MAX_LEVELS. creases: ``(pairs (K, 2) int,
    sharpness (K,) float)`` in OpenSubdiv units (10 = infinitely sharp; `loop_rules.crease_to_sharpness`
    converts Blender's crease) or None; vertex_sharpness: (V,) float or None. boundary: "EDGE_ONLY" (Loop's
    boundary rules) or "EDGE_AND_CORNER" (also keeps boundary vertices with one face fixed).
    point_data: name -> (V, ...) float, interpolated like positions; corner_data: name -> (F, 3, ...) float,
    each on its own face-varying mesh with linear boundaries. progress: callable(done, total) or None.
    dtype: of the output values (float32; float64 for comparisons with other float64 implementations).
    backend: "auto" (OpenCL where it is faster and the creases allow it), "numpy" or "opencl" (`loop_opencl`).
    Returns a `LoopResult`. Raises `InvalidInputError` (bad indices, non-manifold edges, unknown rule, non-finite
    values) and `BudgetError`.
    """
    levels = int(levels)
    if not 0 <= levels <= MAX_LEVELS:
        raise InvalidInputError(f"Loop levels must lie in 0..{MAX_LEVELS}; got {levels}")
    if boundary not in BOUNDARY_RULES:
        raise InvalidInputError(f"Unknown boundary rule {boundary!r}; expected one of {BOUNDARY_RULES}")
    pos = np.asarray(positions, dtype=np.float64)
    if pos.ndim != 2 or pos.shape[1] != 3:
        raise InvalidInputError(f"positions must have shape (V, 3); got {pos.shape}")
    if not np.all(np.isfinite(pos)):
        raise InvalidInputError("The mesh has vertex positions that are NaN or infinite")
    tris = validate_triangles(triangles, len(pos))
    point_shapes = {k: np.shape(v)[1:] for k, v in (point_data or {}).items()}
    corner_shapes = {k: np.shape(v)[2:] for k, v in (corner_data or {}).items()}
    point_data = {k: np.asarray(v, np.float64).reshape(len(pos), -1) for k, v in (point_data or {}).items()}
    corner_data = {k: np.asarray(v, np.float64).reshape(len(tris), 3, -1) for k, v in (corner_data or {}).items()}
    for name, values in (*point_data.items(), *corner_data.items()):
        if not np.all(np.isfinite(values)):
            raise InvalidInputError(f"Attribute {name!r} has values that are NaN or infinite")

    lv = coarse_level(tris, len(pos), creases, vertex_sharpness, sharp_corners=boundary == "EDGE_AND_CORNER")
    widths = [v.shape[1] for v in point_data.values()]
    est = estimate(len(pos), len(lv.edges), len(tris), levels, sum(widths),
                   sum(v.shape[2] for v in corner_data.values()))
    check_budget(est, budget_bytes, "fewer levels")

    runtime = _runtime(backend, lv, est)
    fvars = {}
    for name, values in corner_data.items():
        fv_values, fv_tris = _face_varying(tris, values)
        fvars[name] = (_fvar_coarse(lv, fv_tris, len(fv_values)), fv_values)

    meshes = 1 + len(fvars)
    report = None if progress is None else lambda i: lambda done, _: progress(i * levels + done, meshes * levels)
    coarse_edges = lv.edges
    data, lv = _levels(lv, np.concatenate([pos, *point_data.values()], axis=1), levels, runtime,
                       None if report is None else report(0))
    for i, (name, (flv, fv)) in enumerate(fvars.items()):
        fv, flv = _levels(flv, fv, levels, runtime, None if report is None else report(i + 1))
        fvars[name] = fv[flv.triangles].astype(dtype).reshape((len(flv.triangles), 3, *corner_shapes[name]))

    out_points = {}
    at = 3
    for name, w in zip(point_data, widths, strict=True):
        out_points[name] = data[:, at : at + w].astype(dtype).reshape((-1, *point_shapes[name]))
        at += w
    return LoopResult(
        positions=data[:, :3].astype(dtype),
        triangles=lv.triangles.astype(np.int32, copy=False),
        edges=lv.edges.astype(np.int32, copy=False),
        corner_edges=lv.face_edges.astype(np.int32, copy=False),
        edge_sharpness=lv.edge_sharpness,
        point_attributes=out_points,
        corner_attributes=fvars,
        levels=levels,
        coarse_edges=coarse_edges,
    )

"""Rational Bézier patches of any degree tessellated with per-patch, per-boundary levels, welded with no
T-junction ([Nellmedin 2014, §4.3, §5.5.3]; the Utah teapot's kind of model, and every NURBS surface Blender holds once
`kernels.common.curves.nurbs` has split it into patches).

A patch is its k x k homogeneous control net ``H[i, j] = (w x, w y, w z, w)`` (i along u, j along v; degree k - 1
in both directions: a direction of lower degree is raised exactly, `kernels.common.curves.nurbs.degree_elevate`), and
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
  `kernels.common.curves.step_spacing`, one table for every direction linked through shared sides,
  `direction_chains`); a side's level from the deviation of its chords at 16 steps, a direction's from its
  iso-lines', both scaled as the square root (the deviation of a chord falls with the square of its length); each inner
  grid is then fitted to a model measured on a 12 x 12 probe (`fitted_inner`), and every triangle is measured against
  the surface, before the mesh is made (the inner grids by `grid_deviation`, the strips along the sides by
  `rim_triangles`), raising the levels where it is still over (`TOLERANCE_ROUNDS` times at most), so the tolerance is
  met or the patches that cannot meet it within Max Level are named (and split, `tessellate_surface`);
- any of these together: the largest. Levels are whole segment counts. The inside of a patch has a count of steps
  along u and one along v: the same (the larger) for curvature, distance and edge length, each its own for the
  tolerance."""

import logging
from dataclasses import replace
from functools import cache

import numpy as np

from ...common.budget import check_budget
from ...common.curves.rational_bezier import cartesian
from ...common.errors import OpenCLUnavailableError, TesseraError
from ...common.opencl_runtime import backend_runtime
from .. import patch_deviation_opencl, patch_split
from .deviation import _B, grid_deviation, rim_triangles, triangle_deviation
from .levels import METRICS, PatchLod, Spacing, _sides_keep_up, direction_chains, patch_levels, patch_spacing
from .mesh import PatchMesh, SurfaceTessellation, estimate, tessellate_patches
from .nets import PatchEdges, check_patches, evaluate, patch_edges
from .tolerance import FIT_AIM, FIT_PROBE, _meet_tolerance, fitted_inner, stored_error

#: The entry (`tessellate_surface`) and what the operator, the tests and the benches use of the modules behind it.
__all__ = ["METRICS", "FIT_AIM", "PatchEdges", "PatchLod", "PatchMesh", "Spacing", "SurfaceTessellation", "cartesian",
           "check_patches", "direction_chains", "estimate", "evaluate", "fitted_inner", "grid_deviation",
           "patch_edges", "patch_levels", "patch_spacing", "rim_triangles", "stored_error", "tessellate_surface",
           "tessellate_patches", "triangle_deviation"]


#: With the tolerance, how many times patches still over it at Max Level are split and the whole made again.
SPLIT_ROUNDS = 3

def tessellate_surface(control, lod, camera=None, budget_bytes=None, backend="auto"):
    """Levels from ``lod`` and the welded mesh at them: a `SurfaceTessellation`. With TOLERANCE among the metrics, every
    triangle is measured against the surface (`triangle_deviation`) and each side
    (`kernels.common.curves.rational_bezier.chord_deviation`), and the levels of what is over are raised, until all is
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
    """The OpenCL runtime that measures for `tessellate_surface`'s ``backend`` nets of k x k points, its program built,
    or None (numpy). With "auto", a device without double precision, or whose compiler refuses the program, leaves the
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
    """`tessellate_surface` without splitting: a `SurfaceTessellation` of these patches (parent and box left to the
    caller)."""
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
        return SurfaceTessellation(mesh, el, inner, edges, np.full(len(h), np.nan), np.zeros(0, np.int64))
    return SurfaceTessellation(mesh, el, inner, edges, dev, np.flatnonzero(dev > lod.tolerance))

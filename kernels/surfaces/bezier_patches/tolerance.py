"""The tolerance met: each inner grid fitted to a model measured on a probe (`fitted_inner`), then every triangle
measured against the surface and the levels raised where it is still over (`_meet_tolerance`)."""


import numpy as np

from ...common.budget import check_budget
from ...common.curves.rational_bezier import (
    cartesian,
    chord_deviation,
    steps_for,
)
from .deviation import _deviation, grid_deviation, rim_triangles
from .levels import _sides_keep_up
from .mesh import estimate

#: Rounds of measuring the mesh against the surface and raising levels, for the tolerance.
TOLERANCE_ROUNDS = 16

#: `fitted_inner`'s model of a grid is measured at this many steps each way.
FIT_PROBE = 12

#: `fitted_inner` aims this far under the tolerance: the grids are measured again at the levels it gives, at the
#: same points, so only the model's error needs room.
FIT_AIM = 0.95

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
        new_el, new_inner = _raised(el, inner, edges, rim, side_dev, grid_dev, tol, top)
        changed_sides = new_el != el
        changed = (new_inner != inner).any(axis=1) | changed_sides[edges.edge].any(axis=1)
        if not changed.any():
            return el, inner, dev
        el, inner = new_el, new_inner
    check_budget(estimate(el, inner), budget_bytes, lower)
    return el, inner, measure(el, inner, changed, changed_sides)


def _raised(el, inner, edges, rim, side_dev, grid_dev, tol, top):
    """One round's new levels from what it measured: edge levels (E,) and inner levels (P, 2), at most ``top``.
    rim: the strips' triangles ((u, v) (T, 3, 2), patch (T,), deviation (T,)); side_dev (E,): each side's chords;
    grid_dev (P, 3): each inner grid's deviation and its parts along u and v (`grid_deviation`)."""
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
    rim_need = np.zeros(len(inner))
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
    return np.minimum(_sides_keep_up(new_el, new_inner, edges), top), new_inner

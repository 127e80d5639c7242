"""NURBS splines as Blender holds them, turned into exact rational Bézier pieces ([Piegl 1997, A5.4-A5.6]).

A spline of ``n`` control points (Cartesian point and weight, as Blender's ``SplinePoint.co``), of order ``k``
(degree ``p = k - 1``), gets the knot vector Blender makes for its knot mode (`blender_knots`): UNIFORM, ENDPOINT,
BEZIER or ENDPOINT_BEZIER, cyclic or not; CUSTOM knots are taken as given. A cyclic spline repeats its first
``k - 1`` points at its end (`wrap_cyclic`), so its curve closes. Each knot span of the domain ``[t[p], t[m]]``
(``m`` points after wrapping) is one rational Bézier piece of degree ``p``, found by blossoming in homogeneous
coordinates (``(w x, w y, w z, w)``): the piece's ``r``-th control point is the polar form ``f(a^(p-r), b^r)`` of the
span ``[a, b]``, computed by de Boor's triangle with a different argument on each level — the same points as inserting
every inner knot until its multiplicity is ``p`` (Boehm's insertion, the Oslo algorithm), without changing the curve.
Pieces that meet share their end control point exactly (the second one's copy of it is the first's), so meshes and
polylines built from the pieces weld without a gap; a cyclic spline's last piece ends on its first piece's start.

A surface is the tensor product: its net of ``nv`` rows of ``nu`` points is split along u, row by row, then along v,
column by column, into patches of ``ku x kv`` homogeneous points (`surface_patches`).
"""

from dataclasses import dataclass

import numpy as np

from ..errors import InvalidInputError

KNOT_MODES = ("UNIFORM", "ENDPOINT", "BEZIER", "ENDPOINT_BEZIER", "CUSTOM")
MIN_ORDER, MAX_ORDER = 2, 6


@dataclass(frozen=True)
class Direction:
    """One parameter direction of a spline as Blender holds it: order (2-6), knot mode (one of KNOT_MODES),
    cyclic, and knots (K,) float64 for CUSTOM (``points + order`` values, ``+ order - 1`` when cyclic)."""

    order: int
    mode: str = "ENDPOINT"
    cyclic: bool = False
    knots: tuple = ()


def blender_knots(n_points, order, mode, cyclic):
    """Blender's knot vector of a spline direction: ``n_points + order`` values (``+ order - 1`` cyclic), float64.

    Inner knots step by 1 (repeated ``order - 1`` times in a Bézier mode); an endpoint mode repeats the first knot
    ``order`` times (``order - 1`` cyclic, after a lone first knot), a Bézier mode twice; the last ``order`` knots of
    an endpoint spline, and the last ``2 order - 1`` of a cyclic one, repeat the first ones' spacing."""
    if mode not in KNOT_MODES[:4]:
        raise InvalidInputError(f"Unknown knot mode {mode!r}; expected one of {', '.join(KNOT_MODES[:4])}")
    bezier = mode in ("BEZIER", "ENDPOINT_BEZIER")
    endpoint = mode in ("ENDPOINT", "ENDPOINT_BEZIER")
    repeat_inner = order - 1 if bezier else 1
    head = (order - (1 if cyclic else 0)) if endpoint else (min(2, repeat_inner) if bezier else 1)
    tail = 2 * order - 1 if cyclic else (order if endpoint else 0)
    count = n_points + order + (order - 1 if cyclic else 0)
    knots = np.zeros(count)
    current, r = 0.0, head
    offset = 1 if (endpoint and cyclic) else 0
    if offset:
        knots[0], current = 0.0, 1.0
    for i in range(offset, count - tail):
        knots[i] = current
        r -= 1
        if r == 0:
            current += 1.0
            r = repeat_inner
    start = count - tail
    for i in range(tail):  # in order: a cyclic tail may repeat knots it has just written
        knots[start + i] = current + (knots[i] - knots[0])
    return knots


def homogeneous(points):
    """Cartesian points and weights (..., 4) (Blender's ``co``) -> homogeneous (w x, w y, w z, w) (..., 4)."""
    p = np.asarray(points, np.float64)
    return np.concatenate([p[..., :3] * p[..., 3:4], p[..., 3:4]], axis=-1)


def check_points(points, what="spline"):
    """Refuse control points that are not finite or whose weights are not positive. points: (..., 4)."""
    p = np.asarray(points, np.float64)
    if not np.all(np.isfinite(p)):
        raise InvalidInputError(f"The {what} has control points or weights that are NaN or infinite")
    if np.any(p[..., 3] <= 0):
        raise InvalidInputError(f"The {what} has weights of zero or less ({float(p[..., 3].min()):g}); "
                                "NURBS weights must be positive")
    return p


def direction_knots(n_points, direction, what="spline"):
    """The knots of one direction (validated): (n_points + order [+ order - 1]) float64."""
    k = int(direction.order)
    if not MIN_ORDER <= k <= MAX_ORDER:
        raise InvalidInputError(f"The {what} has order {k}; Tessera takes orders {MIN_ORDER} to {MAX_ORDER}")
    if n_points < 2:
        raise InvalidInputError(f"The {what} has {n_points} point(s) in a direction; it needs at least 2")
    if k > n_points:
        raise InvalidInputError(f"The {what} has order {k} but only {n_points} points in that direction: lower its "
                                f"Order to {n_points} or less")
    count = n_points + k + (k - 1 if direction.cyclic else 0)
    if direction.mode in ("BEZIER", "ENDPOINT_BEZIER"):  # what Blender itself draws as a control polygon only
        need = 0
        if direction.cyclic and n_points % (k - 1):
            need = k - 1 - n_points % (k - 1)
        elif not direction.cyclic and direction.mode == "BEZIER" and n_points <= k:
            need = k + 1 - n_points
        if need:
            raise InvalidInputError(f"The {what} has Bézier knots that need {need} more point(s) at order {k} "
                                    "(Blender draws it as its control polygon): add points, change the Order, or "
                                    "turn off Bézier")
    if direction.mode != "CUSTOM":
        return blender_knots(n_points, k, direction.mode, direction.cyclic)
    knots = np.asarray(direction.knots, np.float64)
    if knots.shape != (count,) or not np.all(np.isfinite(knots)) or np.any(np.diff(knots) < 0):
        raise InvalidInputError(f"The {what}'s custom knots must be {count} finite, non-decreasing values; got "
                                f"{knots.shape[0] if knots.ndim == 1 else knots.shape}")
    return knots


def wrap_cyclic(points, order, cyclic, axis=0):
    """A cyclic direction's points with its first ``order - 1`` repeated at the end (along ``axis``)."""
    p = np.asarray(points)
    if not cyclic:
        return p
    return np.concatenate([p, np.take(p, np.arange(order - 1), axis=axis)], axis=axis)


def spans(knots, order, n_wrapped):
    """Indices i (S,) of the non-empty knot spans ``[t[i], t[i + 1]]`` in the domain ``[t[p], t[n_wrapped]]``."""
    t = np.asarray(knots, np.float64)
    i = np.arange(order - 1, n_wrapped)
    return i[t[i + 1] > t[i]]


def bezier_pieces(points_h, knots, order):
    """Rational Bézier pieces of a B-spline in homogeneous coordinates.

    points_h: (m, d) homogeneous control points (already wrapped if cyclic); knots: (m + order,). Returns
    (pieces (S, order, d) float64, span (S, 2) float64: each piece's knot interval). Consecutive pieces share their
    end point exactly (piece s + 1's first point is piece s's last)."""
    c = np.asarray(points_h, np.float64)
    t = np.asarray(knots, np.float64)
    p = order - 1
    idx = spans(t, order, len(c))
    if len(idx) == 0:
        raise InvalidInputError("The spline's knots leave no span to draw (all its domain knots are equal)")
    a, b = t[idx], t[idx + 1]
    # d[s, r, j]: local control points P[i - p + j] for each output point r of each span s
    d = np.broadcast_to(c[idx[:, None] - p + np.arange(p + 1)[None]][:, None], (len(idx), p + 1, p + 1, c.shape[1]))
    d = d.copy()
    r_out = np.arange(p + 1)
    for level in range(1, p + 1):
        # the argument on this level: a for the first p - r levels, b for the last r (a symmetric polar form)
        u = np.where(level <= p - r_out[None, :], a[:, None], b[:, None])  # (S, p + 1)
        for j in range(p, level - 1, -1):
            lo = t[idx - p + j]
            hi = t[idx + 1 + j - level]
            alpha = (u - lo[:, None]) / (hi - lo)[:, None]
            d[:, :, j] = (1.0 - alpha)[..., None] * d[:, :, j - 1] + alpha[..., None] * d[:, :, j]
    pieces = d[:, :, p]
    pieces[1:, 0] = pieces[:-1, p]
    return pieces, np.stack([a, b], axis=1)


def curve_pieces(points, direction, extra=None, what="curve"):
    """A NURBS curve's rational Bézier pieces: points (n, 4) Cartesian + weight; extra (n, e) values carried along
    the same way (radius, tilt: ``Σ N_i w_i r_i / Σ N_i w_i``, as Blender interpolates them) -> (pieces (S, order,
    4 + e) homogeneous, extra values times w after column 3; span (S, 2)). A cyclic curve's last piece ends exactly
    where its first starts."""
    p = check_points(np.asarray(points, np.float64).reshape(-1, 4), what)
    knots = direction_knots(len(p), direction, what)
    h = homogeneous(p)
    if extra is not None:
        e = np.asarray(extra, np.float64).reshape(len(p), -1)
        if not np.all(np.isfinite(e)):
            raise InvalidInputError(f"The {what} has radius or tilt values that are NaN or infinite")
        h = np.concatenate([h, e * p[:, 3:4]], axis=1)
    pieces, span = bezier_pieces(wrap_cyclic(h, direction.order, direction.cyclic), knots, direction.order)
    if direction.cyclic:
        pieces[-1, -1] = pieces[0, 0]
    return pieces, span


def surface_patches(points, u, v, what="surface"):
    """A NURBS surface's rational Bézier patches.

    points: (nv, nu, 4) Cartesian + weight (row b holds the nu points along u at the b-th v); u, v: `Direction`.
    Returns (patches (Su * Sv, ku, kv, 4) homogeneous, patch[i, j] the point i along u and j along v; grid (Su, Sv)
    shape of the patches, patch q at (q // Sv, q % Sv); spans (Su, 2) and (Sv, 2))."""
    p, knots = _checked_surface(points, u, v, what)
    patches, grid, span_u, span_v = _batch_patches(homogeneous(p)[None], u, v, *knots)
    return patches[0], grid, span_u, span_v


def _checked_surface(points, u, v, what):
    """A surface spline's points (nv, nu, 4) checked (`check_points`) and its knots along u and v
    (`direction_knots`): refusals name it as ``what``."""
    p = check_points(points, what)
    return p, (direction_knots(p.shape[1], u, what), direction_knots(p.shape[0], v, what))


def _batch_patches(h, u, v, ku_knots, kv_knots):
    """`surface_patches` of B splines that share their shape and directions at once: homogeneous points h
    (B, nv, nu, 4) -> (patches (B, Su * Sv, ku, kv, 4), grid, spans). Each coordinate column goes through the knot
    insertions on its own, so a spline's patches are bitwise those it has alone."""
    h = wrap_cyclic(wrap_cyclic(h, u.order, u.cyclic, axis=2), v.order, v.cyclic, axis=1)
    n, mv, mu = h.shape[:3]
    # along u: every row of every spline at once, the rows' coordinates side by side
    rows = h.transpose(2, 0, 1, 3).reshape(mu, n * mv * 4)
    pu, span_u = bezier_pieces(rows, ku_knots, u.order)  # (Su, ku, B * mv * 4)
    if u.cyclic:
        pu[-1, -1] = pu[0, 0]
    su = len(pu)
    cols = pu.reshape(su * u.order, n, mv, 4).transpose(2, 1, 0, 3).reshape(mv, n * su * u.order * 4)
    pv, span_v = bezier_pieces(cols, kv_knots, v.order)  # (Sv, kv, B * Su * ku * 4)
    if v.cyclic:
        pv[-1, -1] = pv[0, 0]
    sv = len(pv)
    patches = pv.reshape(sv, v.order, n, su, u.order, 4).transpose(2, 3, 0, 4, 1, 5)
    return patches.reshape(n, su * sv, u.order, v.order, 4), (su, sv), span_u, span_v


def degree_elevate(pieces, degree):
    """Rational Bézier pieces raised to a higher degree, exactly: (..., k, d) along axis -2 -> (..., degree + 1, d)."""
    c = np.asarray(pieces, np.float64)
    while c.shape[-2] - 1 < degree:
        n = c.shape[-2] - 1
        i = np.arange(1, n + 1)[:, None] / (n + 1)
        inner = i * c[..., :-1, :] + (1 - i) * c[..., 1:, :]
        c = np.concatenate([c[..., :1, :], inner, c[..., -1:, :]], axis=-2)
    return c


@dataclass
class SurfaceSpline:
    """One NURBS surface spline: points (nv, nu, 4) Cartesian + weight (row b: the nu points along u at the b-th v),
    u and v its `Direction` s."""

    points: np.ndarray
    u: Direction
    v: Direction


@dataclass
class PatchSet:
    """Patches of several splines at one degree: patches (P, k, k, 4) homogeneous; spline (P,) int64 the index of
    each patch's spline; box (P, 2, 2) float64 each patch's ((u0, u1), (v0, v1)) in its spline's parameters scaled
    to [0, 1] (for UVs: ``u0 + s (u1 - u0)`` at the patch's own s)."""

    patches: np.ndarray
    spline: np.ndarray
    box: np.ndarray

    def uv(self, patch, st):
        """The splines' (u, v) in [0, 1] of patch-local (s, t): patch (...) int, st (..., 2) -> (..., 2)."""
        b = self.box[patch]
        return b[..., 0] + np.asarray(st, np.float64) * (b[..., 1] - b[..., 0])

    def locate(self, uv, spline=0):
        """Which patch of a spline holds each of its (u, v) in [0, 1] (N, 2), and where in it: (patch (N,) int64,
        st (N, 2) float64). A (u, v) on a border between patches goes to the later one (the last at 1)."""
        q = np.flatnonzero(self.spline == spline)
        b = self.box[q]
        u0, v0 = np.unique(b[:, 0, 0]), np.unique(b[:, 1, 0])
        uv = np.asarray(uv, np.float64)
        iu = np.clip(np.searchsorted(u0, uv[:, 0], side="right") - 1, 0, len(u0) - 1)
        iv = np.clip(np.searchsorted(v0, uv[:, 1], side="right") - 1, 0, len(v0) - 1)
        patch = q[iu * len(v0) + iv]  # a spline's patches run u-major
        lo, hi = self.box[patch, :, 0], self.box[patch, :, 1]
        return patch, (uv - lo) / (hi - lo)


def patches_of(splines, numbers=None):
    """Every `SurfaceSpline`'s rational Bézier patches, raised to one degree: a `PatchSet`. Raising a degree moves
    no point of the surface, and the sides that patches of one spline share stay bitwise equal (the same numbers go
    through the same steps). numbers: how a refusal names each spline (its place in Blender's list; by default
    its place in ``splines``)."""
    if not splines:
        raise InvalidInputError("There is no surface spline to tessellate")
    numbers = range(len(splines)) if numbers is None else numbers
    # each spline checked on its own (a refusal names it); splines of one shape and the same directions (a model of
    # many Bézier patches) then go through the knot insertions together
    groups = {}
    for i, sp in enumerate(splines):
        p, knots = _checked_surface(sp.points, sp.u, sp.v, f"surface spline {numbers[i]}")
        groups.setdefault((p.shape, sp.u, sp.v), (knots, []))[1].append((i, homogeneous(p)))
    made = {}
    for (_, u, v), (knots, members) in groups.items():
        patches, grid, span_u, span_v = _batch_patches(np.stack([h for _, h in members]), u, v, *knots)
        for (i, _), own in zip(members, patches, strict=True):
            made[i] = own, grid, span_u, span_v
    parts, owner, boxes = [], [], []
    for i in range(len(splines)):
        patches, (su, sv), span_u, span_v = made[i]
        parts.append(patches)
        owner.append(np.full(len(patches), i, np.int64))
        nu = (span_u - span_u[0, 0]) / (span_u[-1, 1] - span_u[0, 0])
        nv = (span_v - span_v[0, 0]) / (span_v[-1, 1] - span_v[0, 0])
        boxes.append(np.stack([np.repeat(nu, sv, axis=0), np.tile(nv, (su, 1))], axis=1))
    k = max(max(p.shape[1], p.shape[2]) for p in parts)
    out = []
    for p in parts:
        p = degree_elevate(p.transpose(0, 2, 1, 3), k - 1).transpose(0, 2, 1, 3)  # along u
        out.append(degree_elevate(p, k - 1))  # along v
    return PatchSet(np.concatenate(out), np.concatenate(owner), np.concatenate(boxes))


def knot_mode(endpoint, bezier):
    """Blender's knot flags of a direction (Endpoint, Bezier) as one of KNOT_MODES."""
    if endpoint and bezier:
        return "ENDPOINT_BEZIER"
    return "ENDPOINT" if endpoint else ("BEZIER" if bezier else "UNIFORM")

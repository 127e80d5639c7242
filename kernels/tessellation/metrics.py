"""Adaptive tessellation metrics as pure functions ([Nellmedin 2014, ch. 4], with its corrections).

Each metric maps per-edge data to a level, so the two triangles of a shared edge compute the same
value bit for bit (the crack-free rule): every edge function is symmetric in its two endpoints
(``a + b`` and ``(a - b)^2`` are exact under swapping) and uses nothing but that edge's data. Inner
levels may use the whole triangle. Levels are float64; `clamp_and_round` applies the cap and the
optional power-of-two rounding at the end.

Functions take arrays with a leading "any" shape ``(...)`` so the same code serves per-edge ``(E,)``
and per-face-side ``(T, 3)`` inputs (the latter is how a GPU patch sees them; tests compare the two).
"""

import numpy as np

from ..common.errors import InvalidInputError
from ..common.level_metrics import (  # noqa: F401 (eqs. 4.1-4.5, part of the metrics)
    DISTANCE_MAPS,
    curvature_level,
    curve_kappa,
    distance_level,
    projected_sphere_levels,
)
from ..common.partition import MAX_LEVEL

POWER_OF_TWO = ("NONE", "CEIL", "FLOOR", "NEAREST")


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def edge_midpoints(a, b):
    """(..., 3) x2 -> (..., 3) float64, symmetric in ``a`` and ``b``."""
    return (np.asarray(a, np.float64) + np.asarray(b, np.float64)) * 0.5


def distance_edge_levels(a, b, eye, d_min, d_max, t_max, mapping="LINEAR"):
    """Distance metric per edge, from the distance of the edge midpoint to the eye: (..., 3) x2 -> (...)."""
    m = edge_midpoints(a, b) - np.asarray(eye, np.float64)
    return distance_level(np.sqrt(_dot(m, m)), d_min, d_max, t_max, mapping)


def distance_inner_levels(corners, eye, d_min, d_max, t_max, mapping="LINEAR"):
    """Distance metric inner level from the triangle centroid: (T, 3, 3) -> (T,)."""
    c = np.asarray(corners, np.float64).mean(axis=1) - np.asarray(eye, np.float64)
    return distance_level(np.sqrt(_dot(c, c)), d_min, d_max, t_max, mapping)


def to_eye(points, view):
    """World points (..., 3) -> eye space (..., 3) with a (4, 4) row-major view matrix."""
    view = np.asarray(view, np.float64)
    return np.asarray(points, np.float64) @ view[:3, :3].T + view[:3, 3]


def projected_edge_levels(a, b, view, projection, height, e_max, t_max=MAX_LEVEL):
    """Largest projected length of each edge in pixels over ``e_max`` ([Nellmedin 2014, §4.4, correction 2]).

    The edge is treated as a sphere of diameter ``|b - a|`` at its midpoint: the midpoint ``m`` and
    ``m + (0, |b - a|, 0)`` are taken in **eye space** and projected, so the result does not depend on
    the edge's orientation. ``l_s = |y_ndc(m') - y_ndc(m)| * height / 2``, level ``l_s / e_max``.

    a, b: (..., 3) world points; view, projection: (4, 4) row-major; height: viewport height in pixels.
    An edge whose sphere reaches behind the eye plane gets ``t_max``; one entirely behind gets 1.
    Returns (...) float64 in ``[1, t_max]``.
    """
    if e_max <= 0:
        raise InvalidInputError("The target edge length in pixels must be positive")
    pa, pb = to_eye(a, view), to_eye(b, view)
    diff = pa - pb
    return projected_sphere_levels((pa + pb) * 0.5, np.sqrt(_dot(diff, diff)), projection, height, e_max, t_max)


def face_normals(corners):
    """Unnormalised face normals ``(p1 - p0) x (p2 - p0)``: (T, 3, 3) -> (T, 3) float64."""
    p = np.asarray(corners, np.float64)
    return np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])


def silhouette_products(a, b, n_this, n_other, eye):
    """Eq. 4.7 and 4.8 per edge: ``u = (v·n_this)(v·n_other)`` and its normalised form, ``v = eye - mid``.

    a, b: (..., 3) edge endpoints; n_this, n_other: (..., 3) unit normals of the two faces. The product
    is commutative, so either face computes the same value. Returns ``(u, u_hat)``, (...) float64 each.
    """
    v = np.asarray(eye, np.float64) - edge_midpoints(a, b)
    x, y = _dot(v, np.asarray(n_this, np.float64)), _dot(v, np.asarray(n_other, np.float64))
    vv = _dot(v, v)
    u = x * y
    u_hat = np.divide(u, vv, out=np.zeros_like(u), where=vv > 0)
    return u, u_hat


def silhouette_edge_levels(u, t_max):
    """Eq. 4.9: ``t_max`` where the edge is a silhouette (``u < 0``), else 1. (...) -> (...)."""
    return np.where(np.asarray(u) < 0, float(t_max), 1.0)


def silhouette_inner_levels(u, u_hat, t_max, beta):
    """Eq. 4.10 per face from its edges' ``u`` and ``u_hat`` (T, 3): the largest ramp over silhouette edges.

    ``t = t_max - (t_max - 1) |u_hat| / beta`` where ``u <= 0`` and ``|u_hat| <= beta``, else 1.
    """
    if beta <= 0:
        raise InvalidInputError("The silhouette ramp width beta must be positive")
    u, u_hat = np.asarray(u, np.float64), np.abs(np.asarray(u_hat, np.float64))
    ramp = t_max - (t_max - 1.0) * u_hat / beta
    t = np.where((u <= 0) & (u_hat <= beta), ramp, 1.0)
    return t.max(axis=-1)


def pn_inner_kappa(control):
    """Curvature of the three interior isocurves of a cubic triangle net, through b111. (T, 10, 3) -> (T,).

    Rows (in `kernels.tessellation.patches.cubic_basis` order): b120-b111-b102, b210-b111-b012, b201-b111-b021.
    """
    c = np.asarray(control, np.float64)
    rows = np.stack([c[:, [4, 9, 7]], c[:, [3, 9, 6]], c[:, [8, 9, 5]]], axis=1)
    return curve_kappa(rows).max(axis=1)


def clamp_and_round(levels, t_max=MAX_LEVEL, power_of_two="NONE"):
    """Clamp to ``[1, t_max]`` (``t_max <= 64``) and optionally round to a power of two.

    ``CEIL`` is the default ([Nellmedin 2014, correction 1]) (18 and 20 -> 32); ``FLOOR`` and ``NEAREST`` (nearest in
    log2) are options. A rounded level never exceeds the largest power of two ``<= t_max``.
    """
    if not 1 <= t_max <= MAX_LEVEL:
        raise InvalidInputError(f"The maximum level must lie in [1, {MAX_LEVEL}]; got {t_max}")
    t = np.clip(np.asarray(levels, np.float64), 1.0, float(t_max))
    if power_of_two == "NONE":
        return t
    if power_of_two not in POWER_OF_TWO:
        raise InvalidInputError(f"Unknown power-of-two rounding {power_of_two!r}")
    exponent = np.log2(t)
    rounder = {"CEIL": np.ceil, "FLOOR": np.floor, "NEAREST": np.round}[power_of_two]
    cap = np.floor(np.log2(float(t_max)))
    return np.exp2(np.minimum(rounder(exponent), cap))

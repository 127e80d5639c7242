"""Weights of Loop subdivision in the factored form ([Concheiro et al.], [Warren 2004]) and OpenSubdiv's crease
arithmetic.

One iteration is linear subdivision (a midpoint on every edge), averaging (each vertex moves to
``1/4 v + 3/(4n) * sum of its n neighbours in the linearly subdivided mesh``) and a correction
``v + cf(n) (v' - v)`` with ``cf(n) = 5/3 - 8/3 (3/8 + 1/4 cos(2 pi / n))^2``. That equals Loop's rule with
``beta(n) = (5/8 - (3/8 + 1/4 cos(2 pi / n))^2) / n`` ([Loop 1987]'s weights: [Concheiro et al., correction 1]).

Creases follow OpenSubdiv's uniform rule: sharpness ``s`` (10 = infinitely sharp) drops by 1 per level; an
edge with ``s >= 1`` takes the crease rule (the midpoint), ``0 < s < 1`` blends ``s * crease + (1 - s) *
smooth``; a vertex takes the smooth rule with fewer than two sharp edges (a dart with one), the crease rule
``1/2 v + 1/4 (m1 + m2)`` (= 3/4 v + 1/8 (b1 + b2)) with two, the corner rule (fixed) with more or with a
sharpness of its own; where the rule changes between a level and the next, the two are blended by the average
sharpness of the edges (and vertex) that become smooth (OpenSubdiv's fractional weight, capped at 1).
"""

import numpy as np

SHARPNESS_INFINITE = 10.0
RULE_SMOOTH, RULE_CREASE, RULE_CORNER = 0, 1, 2


def correction_factor(valence):
    """cf(n) of the factored form for valences (K,) int -> (K,) float64 (cf(6) = 1 within one ulp)."""
    n = np.asarray(valence, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        inner = 0.375 + 0.25 * np.cos(2.0 * np.pi / n)
    return 5.0 / 3.0 - 8.0 / 3.0 * inner * inner


def correction_table(max_valence):
    """cf(n) for n = 0..max_valence: (max_valence + 1,) float64, precomputed once per mesh (0 for n < 3,
    where no vertex takes the smooth rule)."""
    table = np.zeros(max(int(max_valence), 3) + 1)
    table[3:] = correction_factor(np.arange(3, len(table)))
    return table


def loop_beta(valence):
    """Loop's neighbour weight beta(n) = (5/8 - (3/8 + 1/4 cos(2 pi / n))^2) / n: (K,) -> (K,) float64."""
    n = np.asarray(valence, dtype=np.float64)
    inner = 0.375 + 0.25 * np.cos(2.0 * np.pi / n)
    return (0.625 - inner * inner) / n


def crease_to_sharpness(crease):
    """Blender's crease (0..1) as OpenSubdiv sharpness, the way Blender's own subdivision converts it:
    ``crease^2 * 10`` (1.0 -> 10, infinitely sharp). (K,) -> (K,) float32."""
    c = np.clip(np.asarray(crease, dtype=np.float32), 0.0, 1.0)
    return (c * c * np.float32(SHARPNESS_INFINITE)).astype(np.float32)


def child_sharpness(sharpness):
    """Sharpness one level down (uniform rule): infinite stays, else ``max(s - 1, 0)``. (K,) float32."""
    s = np.asarray(sharpness, dtype=np.float32)
    return np.where(s >= SHARPNESS_INFINITE, s, np.maximum(s - np.float32(1.0), np.float32(0.0))).astype(np.float32)


def vertex_rule(vertex_sharpness, sharp_edge_count):
    """Rule per vertex from its own sharpness (K,) and its number of sharp incident edges (K,) int."""
    rule = np.where(sharp_edge_count >= 2, RULE_CREASE, RULE_SMOOTH)
    rule = np.where(sharp_edge_count > 2, RULE_CORNER, rule)
    return np.where(np.asarray(vertex_sharpness) > 0, RULE_CORNER, rule).astype(np.int8)

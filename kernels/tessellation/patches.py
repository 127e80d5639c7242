"""Curved triangle patches: PN triangles (Vlachos et al. 2001) and Phong tessellation (Boubekeur & Alexa 2008).

Every surface here is a polynomial in the barycentric coordinates ``b = (b0, b1, b2)`` of a triangle
(corner ``i`` at ``b_i = 1``; in [Nunes 2011]'s notation ``w = b0``, ``u = b1``, ``v = b2``, so corner 0 is
P1 / b300, corner 1 is P2 / b030, corner 2 is P3 / b003). A patch is a control array ``(..., K, C)``
and a basis ``(P, K)`` evaluated at points; the value is ``basis @ control``. Bases carry their
multinomial coefficients, so controls are the textbook control points.

Bases (columns, in order):

- ``linear_basis``: ``b0, b1, b2``.
- ``quadratic_basis``: ``b0^2, b1^2, b2^2, b0 b1, b1 b2, b2 b0`` (mixed coefficient **1**: the PN normal
  patch as published, and the natural form of Phong tessellation).
- ``cubic_basis``: ``b0^3, b1^3, b2^3, 3 b0^2 b1, 3 b0 b1^2, 3 b1^2 b2, 3 b1 b2^2, 3 b0 b2^2, 3 b0^2 b2,
  6 b0 b1 b2`` for the control points ``b300 b030 b003 b210 b120 b021 b012 b102 b201 b111``.

Edges: the restriction of a patch to an edge depends only on that edge's two endpoints and normals.
``*_edge_control`` builds it per mesh edge, in the canonical direction, so the points of a shared edge
are computed once and are bit-identical for both triangles ([Nunes 2011, ch. 3]). Edge bases take the
parameter ``t`` from the first endpoint ``a`` to the second ``b``.

Corrections applied ([Nunes 2011, corrections 2 and 3]): the v_ij denominator is ``(Pj - Pi)·(Pj - Pi)``; the B201
weight is ``3 w^2 v``. Degenerate input (zero-length edges, opposite normals) gives finite values, never NaN.
"""

import numpy as np

#: Index pairs of the mixed terms of `quadratic_basis`, in column order 3, 4, 5.
QUADRATIC_PAIRS = ((0, 1), (1, 2), (2, 0))


def linear_basis(bary):
    """(P, 3) barycentrics -> (P, 3) float64."""
    return np.asarray(bary, dtype=np.float64)


def _corners(bary):
    b = np.asarray(bary, dtype=np.float64)
    return b[:, 0], b[:, 1], b[:, 2]


def _product(out, first, *factors):
    """``first * factors[0] * ...`` left to right, into ``out`` (one row of a basis)."""
    np.multiply(first, factors[0], out=out)
    for f in factors[1:]:
        out *= f


def quadratic_basis(bary):
    """(P, 3) barycentrics -> (P, 6) float64, columns as in the module docstring (the transpose of a (6, P) array:
    each column is one flat run)."""
    b0, b1, b2 = _corners(bary)
    out = np.empty((6, len(b0)))
    for row, pair in zip(out, ((b0, b0), (b1, b1), (b2, b2), (b0, b1), (b1, b2), (b2, b0)), strict=True):
        _product(row, *pair)
    return out.T


def cubic_basis(bary):
    """(P, 3) barycentrics -> (P, 10) float64, columns as in the module docstring."""
    b0, b1, b2 = _corners(bary)
    out = np.empty((10, len(b0)))  # filled by rows and returned transposed: each column is one flat run
    for row, x in zip(out[:3], (b0, b1, b2), strict=True):
        _product(row, x, x, x)  # products, not pow: pow's SIMD paths round differently per CPU
    # Left to right as written, ``3 * b0 * b0 * b1`` is ((3 b0) b0) b1: the shared leading products are the same
    # roundings, so each column has the bits of its expression evaluated alone.
    three0, three1 = 3 * b0, 3 * b1
    t00, t11 = three0 * b0, three1 * b1
    _product(out[3], t00, b1)  # 3 b0 b0 b1
    _product(out[4], three0, b1, b1)  # 3 b0 b1 b1
    _product(out[5], t11, b2)  # 3 b1 b1 b2
    _product(out[6], three1, b2, b2)  # 3 b1 b2 b2
    _product(out[7], three0, b2, b2)  # 3 b0 b2 b2
    _product(out[8], t00, b2)  # 3 b0 b0 b2
    _product(out[9], 6 * b0, b1, b2)  # 6 b0 b1 b2
    return out.T


def linear_edge_basis(t):
    """(P,) parameters -> (P, 2) float64 for controls ``[a, b]``."""
    t = np.asarray(t, dtype=np.float64)
    return np.stack([1.0 - t, t], axis=1)


def quadratic_edge_basis(t):
    """(P,) parameters -> (P, 3) float64 for controls ``[a, b, mid]`` (mixed coefficient 1)."""
    t = np.asarray(t, dtype=np.float64)
    s = 1.0 - t
    return np.stack([s * s, t * t, s * t], axis=1)


def cubic_edge_basis(t):
    """(P,) parameters -> (P, 4) float64 for the Bézier controls ``[a, near a, near b, b]``."""
    t = np.asarray(t, dtype=np.float64)
    s = 1.0 - t
    return np.stack([s * s * s, 3 * s * s * t, 3 * s * t * t, t * t * t], axis=1)


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def _safe_normalize(v):
    length = np.sqrt(_dot(v, v))[..., None]
    return np.divide(v, length, out=np.zeros_like(v), where=length > 0)


def _tangent_point(pi, pj, ni):
    """The cubic control point next to ``pi`` on edge ``pi -> pj``: ``(2 Pi + Pj - w_ij Ni) / 3`` (3-7)."""
    w = _dot(pj - pi, ni)[..., None]
    return (2.0 * pi + pj - w * ni) / 3.0


def _reflected_mid_normal(pi, pj, ni, nj):
    """PN edge normal ``normalize(Ni + Nj - v_ij (Pj - Pi))`` with the corrected v_ij (3-19..3-22)."""
    d = pj - pi
    dd = _dot(d, d)
    v = np.divide(2.0 * _dot(d, ni + nj), dd, out=np.zeros_like(dd), where=dd > 0)
    return _safe_normalize(ni + nj - v[..., None] * d)


def _as64(*arrays):
    return tuple(np.asarray(a, dtype=np.float64) for a in arrays)


def pn_control(positions, normals):
    """PN geometry control points per triangle.

    positions, normals: (T, 3, 3) corner positions and unit normals. Returns (T, 10, 3) float64 in the
    order of `cubic_basis`.
    """
    p, n = _as64(positions, normals)
    p1, p2, p3 = p[:, 0], p[:, 1], p[:, 2]
    n1, n2, n3 = n[:, 0], n[:, 1], n[:, 2]
    b210 = _tangent_point(p1, p2, n1)
    b120 = _tangent_point(p2, p1, n2)
    b021 = _tangent_point(p2, p3, n2)
    b012 = _tangent_point(p3, p2, n3)
    b102 = _tangent_point(p3, p1, n3)
    b201 = _tangent_point(p1, p3, n1)
    e = (b210 + b120 + b021 + b012 + b102 + b201) / 6.0
    v = (p1 + p2 + p3) / 3.0
    b111 = e + (e - v) / 2.0
    return np.stack([p1, p2, p3, b210, b120, b021, b012, b102, b201, b111], axis=1)


def pn_normal_control(positions, normals):
    """PN quadratic normal controls per triangle: (T, 3, 3), (T, 3, 3) -> (T, 6, 3) float64.

    Order of `quadratic_basis`: N1, N2, N3, n110, n011, n101.
    """
    p, n = _as64(positions, normals)
    mids = [_reflected_mid_normal(p[:, i], p[:, j], n[:, i], n[:, j]) for i, j in QUADRATIC_PAIRS]
    return np.stack([n[:, 0], n[:, 1], n[:, 2], *mids], axis=1)


def pn_edge_control(pa, pb, na, nb):
    """The PN boundary cubic of edges ``a -> b``: (E, 3) x4 -> (E, 4, 3) float64 for `cubic_edge_basis`."""
    pa, pb, na, nb = _as64(pa, pb, na, nb)
    return np.stack([pa, _tangent_point(pa, pb, na), _tangent_point(pb, pa, nb), pb], axis=-2)


def pn_edge_normal_control(pa, pb, na, nb):
    """The PN quadratic normal of edges ``a -> b``: -> (E, 3, 3) float64 for `quadratic_edge_basis`."""
    pa, pb, na, nb = _as64(pa, pb, na, nb)
    return np.stack([na, nb, _reflected_mid_normal(pa, pb, na, nb)], axis=-2)


def _phong_mixed(pi, pj, ni, nj, alpha_i, alpha_j):
    """``Pi + Pj - (a_i d_ij Ni + a_j d_ji Nj)`` with ``d_ij = (Pj - Pi)·Ni``."""
    dij = _dot(pj - pi, ni)[..., None]
    dji = _dot(pi - pj, nj)[..., None]
    return pi + pj - (alpha_i * dij * ni + alpha_j * dji * nj)


def phong_control(positions, normals, alpha=0.75):
    """Phong tessellation as a quadratic patch: (T, 3, 3), (T, 3, 3) -> (T, 6, 3) float64.

    ``p*_a = (1 - a) p + a sum_i b_i pi_i(p)`` with ``pi_i(q) = q - ((q - p_i)·n_i) n_i`` expands to the
    quadratic controls ``c_ii = P_i`` and ``c_ij = P_i + P_j - a (d_ij N_i + d_ji N_j)`` exactly. ``alpha``:
    a constant shape factor (0: linear, 1: [Nunes 2011]). For per-vertex factors see `phong_offset_control`.
    """
    p, n = _as64(positions, normals)
    a = float(alpha)
    mixed = [_phong_mixed(p[:, i], p[:, j], n[:, i], n[:, j], a, a) for i, j in QUADRATIC_PAIRS]
    return np.stack([p[:, 0], p[:, 1], p[:, 2], *mixed], axis=1)


def phong_offset_control(positions, normals):
    """The full-Phong offset ``p*(b) - p(b)`` as a quadratic patch with zero corners: -> (T, 6, 3).

    With a per-vertex shape factor interpolated linearly, ``a(b)``, the surface is
    ``p(b) + a(b) (p*(b) - p(b))`` (Boubekeur & Alexa), a cubic evaluated as linear + linear x quadratic.
    """
    p, n = _as64(positions, normals)
    zero = np.zeros_like(p[:, 0])
    mixed = [_phong_mixed(p[:, i], p[:, j], n[:, i], n[:, j], 1.0, 1.0) - p[:, i] - p[:, j]
             for i, j in QUADRATIC_PAIRS]
    return np.stack([zero, zero, zero, *mixed], axis=1)


def phong_edge_control(pa, pb, na, nb, alpha_a=0.75, alpha_b=0.75):
    """Phong on edges ``a -> b``: -> (E, 3, 3) float64 for `quadratic_edge_basis`.

    alpha_a, alpha_b: scalars or (E,) shape factors. On an edge the per-vertex form ``p + a(t) (p* - p)``
    is cubic, so with unequal factors use `phong_edge_offset_control` instead.
    """
    pa, pb, na, nb = _as64(pa, pb, na, nb)
    aa = np.asarray(alpha_a, dtype=np.float64)[..., None] if np.ndim(alpha_a) else float(alpha_a)
    ab = np.asarray(alpha_b, dtype=np.float64)[..., None] if np.ndim(alpha_b) else float(alpha_b)
    return np.stack([pa, pb, _phong_mixed(pa, pb, na, nb, aa, ab)], axis=-2)


def phong_edge_offset_control(pa, pb, na, nb):
    """Full-Phong offset on edges ``a -> b``: -> (E, 3, 3) float64 for `quadratic_edge_basis` (zero ends)."""
    pa, pb, na, nb = _as64(pa, pb, na, nb)
    zero = np.zeros_like(pa)
    return np.stack([zero, zero, _phong_mixed(pa, pb, na, nb, 1.0, 1.0) - pa - pb], axis=-2)


def project_to_plane(q, point, normal):
    """``pi(q) = q - ((q - point)·normal) normal``: the orthogonal projection onto a plane. (..., 3) each."""
    q, point, normal = _as64(q, point, normal)
    return q - _dot(q - point, normal)[..., None] * normal


def phong_direct(positions, normals, bary, alpha=1.0):
    """Phong tessellation evaluated literally from [Nunes 2011]'s projections (3-25), for checking.

    positions, normals: (3, 3) one triangle; bary: (P, 3). Returns (P, 3) float64.
    """
    p, n, b = _as64(positions, normals, bary)
    q = b @ p
    star = sum(b[:, i, None] * project_to_plane(q, p[i], n[i]) for i in range(3))
    return (1.0 - alpha) * q + alpha * star

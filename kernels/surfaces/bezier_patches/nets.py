"""Rational Bézier patch nets: homogeneous nets, evaluation (points, normals, grids by tensor contraction), the
checks every entry makes, and the shared sides (`patch_edges`): each side keyed by its control points, so patches
that share a side share its vertices."""

from dataclasses import dataclass

import numpy as np

from ...common.curves.rational_bezier import (
    bernstein,
    bernstein_derivative,
    cartesian,
)
from ...common.errors import InvalidInputError

#: A side whose control points are all within this fraction of the model's size of its first is one point (a pole).
COLLAPSED = 1e-12

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

def inner_pairs(inner_levels, count):
    """Inner levels as (P, 2) int64 steps along u and along v: (P,) (the same both ways) or (P, 2) as given."""
    n = np.asarray(inner_levels, np.int64)
    n = np.stack([n, n], 1) if n.ndim == 1 else n
    if n.shape != (count, 2):
        raise InvalidInputError(f"Inner levels must be (P,) or (P, 2) for {count} patches; got {n.shape}")
    return np.maximum(n, 1)

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

"""The relief-texture pre-warp (Oliveira, Bishop & McAllister 2000; [Clua et al.], eq. 7 with its correction 1).

Convention ([Clua et al., correction 1]): the source is a parallel-projection image with depth. Texel (u, v)
with orthogonal displacement d is the point ``x = C_s + u a + v b + d f``: a and b the texel axes (their lengths
the texel size), f the unit normal towards the displaced side. With c = C_s - C_d (C_d the destination centre of
projection)::

    k1 = f.(b x c) / a.(b x c),  k2 = f.(c x a) / b.(c x a),  k3 = f.(a x b) / c.(a x b)   (once per C_d)
    u_i = (u + k1 d) / (1 + k3 d),  v_i = (v + k2 d) / (1 + k3 d)

is where the ray from C_d through x meets the source plane (the printed eq. 7's minus signs and its u_f in the v
numerator are [Clua et al., correction 1]). Where 1 + k3 d → 0 the ray runs parallel to the plane (C_d level with the
displaced texel): such texels are marked invalid, never divided.

Occlusion-compatible order ([McMillan 1997]; [Clua et al., correction 2]): the epipole is where the line through C_d
along f meets the plane; the image is split into four quadrants there and each is traversed from its edges towards the
epipole. Painting in that order, a later texel is never farther from C_d than an earlier one landing on the same point:
the higher texel wins a collision, with no depth buffer. A rule read from the paper's text reverses the order when C_d
is behind; that is McMillan's rule for a *perspective* source, whose centre of projection an eye can be behind. A relief
texture is a parallel projection, its centre at infinity along f: with C_d behind the plane the texels move towards the
epipole instead of away from it, and the one nearer C_d is still the one nearer the epipole, so the order stays edges to
epipole. The depth-buffered oracle agrees on both sides (tests), the reversed order does not (83% on the same case).
`forward_splat` paints colours and source addresses (the offset map) that way;
`zbuffer_splat` is the oracle that keeps the nearest texel per destination by depth.
"""

from dataclasses import dataclass

import numpy as np

from ..common.errors import InvalidInputError
from ..common.tolerances import FLOAT64_TINY

#: |1 + k3 d| below this: the ray from C_d is parallel to the source plane (no pre-warped position).
PARALLEL_EPS = 1e-12


@dataclass(frozen=True)
class ReliefFrame:
    """The source image's frame: origin (3,), texel axes a, b (3,) (lengths = texel size), unit normal f (3,)
    towards the displaced side."""

    origin: np.ndarray
    a: np.ndarray
    b: np.ndarray
    f: np.ndarray

    def point(self, u, v, d):
        """World points x = C_s + u a + v b + d f for texel coordinates and displacements (...): (..., 3)."""
        u, v, d = (np.asarray(x, np.float64)[..., None] for x in (u, v, d))
        return self.origin + u * self.a + v * self.b + d * self.f


def prewarp_constants(frame, eye):
    """(k1, k2, k3) for the destination centre of projection ``eye`` (3,): computed once per C_d."""
    a, b, f = (np.asarray(x, np.float64) for x in (frame.a, frame.b, frame.f))
    c = np.asarray(frame.origin, np.float64) - np.asarray(eye, np.float64)
    den = (np.dot(a, np.cross(b, c)), np.dot(b, np.cross(c, a)), np.dot(c, np.cross(a, b)))
    if min(abs(x) for x in den) < FLOAT64_TINY:
        raise InvalidInputError("The destination centre of projection lies in the source plane: no pre-warp")
    return (np.dot(f, np.cross(b, c)) / den[0], np.dot(f, np.cross(c, a)) / den[1], np.dot(f, np.cross(a, b)) / den[2])


def prewarp(u, v, d, k):
    """Eq. 7 (corrected): pre-warped texel coordinates (u_i, v_i) and valid (...) bool (False where 1 + k3 d is
    within `PARALLEL_EPS` of 0; u_i, v_i are NaN there)."""
    k1, k2, k3 = k
    u, v, d = (np.asarray(x, np.float64) for x in (u, v, d))
    den = 1.0 + k3 * d
    valid = np.abs(den) > PARALLEL_EPS
    safe = np.where(valid, den, 1.0)
    ui = np.where(valid, (u + k1 * d) / safe, np.nan)
    vi = np.where(valid, (v + k2 * d) / safe, np.nan)
    return ui, vi, valid


def ray_plane_reference(frame, eye, u, v, d):
    """The oracle of eq. 7: where the ray from ``eye`` through the texel's point meets the source plane, solved as a
    3 x 3 system per texel: (u_i, v_i) (...)."""
    x = frame.point(u, v, d)
    eye = np.asarray(eye, np.float64)
    a, b = (np.broadcast_to(np.asarray(axis, np.float64), x.shape) for axis in (frame.a, frame.b))
    m = np.stack([a, b, -(x - eye)], axis=-1)  # C_s + u a + v b = eye + t (x - eye)
    rhs = np.broadcast_to(eye - np.asarray(frame.origin, np.float64), x.shape)
    sol = np.linalg.solve(m, rhs[..., None])[..., 0]
    return sol[..., 0], sol[..., 1]


def epipole(frame, eye):
    """Where the line through ``eye`` along f meets the source plane, in texel coordinates, and the eye's height
    above the plane along f: (u_e, v_e, h). h > 0: the eye is in front (on the displaced side)."""
    m = np.stack([frame.a, frame.b, frame.f], axis=-1)
    u, v, h = np.linalg.solve(m, np.asarray(eye, np.float64) - np.asarray(frame.origin, np.float64))
    return float(u), float(v), float(h)


def traversal_rank(width, height, frame, eye):
    """Each texel's place in the occlusion-compatible painting order: (H, W) int64, 0 painted first.

    Texels are ranked by their distance to the epipole in rows (v), then in columns (u), farthest first (edges
    towards the epipole); within each of the four quadrants that is [Clua et al.]'s row-by-row traversal, and across
    quadrants it is consistent (they never overlap). The order is the same with the eye behind the plane: see the
    module docstring."""
    ue, ve, _ = epipole(frame, eye)
    v, u = np.mgrid[0:height, 0:width]
    dv, du = np.abs(v + 0.5 - ve), np.abs(u + 0.5 - ue)
    keys = (-du, -dv)  # lexsort: the last key is the primary one
    order = np.lexsort((keys[0].ravel(), keys[1].ravel()))
    rank = np.empty(width * height, np.int64)
    rank[order] = np.arange(width * height)
    return rank.reshape(height, width)


def _destinations(width, height, frame, eye, displacement, present=None):
    """Nearest destination texel of every source texel: (flat index (N,) int64, inside (N,) bool); texels outside
    ``present`` (H, W) bool (where the object is not: its image's background) go nowhere."""
    k = prewarp_constants(frame, eye)
    v, u = np.mgrid[0:height, 0:width]
    ui, vi, valid = prewarp(u + 0.5, v + 0.5, displacement, k)  # texel centres
    iu, iv = np.floor(np.where(valid, ui, -1.0)), np.floor(np.where(valid, vi, -1.0))
    inside = valid & (iu >= 0) & (iu < width) & (iv >= 0) & (iv < height)
    if present is not None:
        inside &= np.asarray(present, bool)
    flat = np.where(inside, iv * width + iu, 0).astype(np.int64).ravel()
    return flat, inside.ravel()


@dataclass
class Splat:
    """A pre-warped image: source (H, W) int64, the flat index of the source texel painted at each destination
    texel (-1: a hole) — the offset map; offsets (H, W, 2) float32 its source texel centres (u, v), NaN in holes."""

    source: np.ndarray

    @property
    def offsets(self):
        h, w = self.source.shape
        s = self.source
        uv = np.stack([s % w + 0.5, s // w + 0.5], -1).astype(np.float32)
        uv[s < 0] = np.nan
        return uv

    @property
    def hole_fraction(self):
        return float((self.source < 0).mean())

    def gather(self, image):
        """The source image's texels (H, W, ...) at the offset map: the pre-warped image (holes 0)."""
        img = np.asarray(image)
        flat = img.reshape(self.source.size, *img.shape[2:])
        out = flat[np.maximum(self.source.ravel(), 0)].copy()
        out[self.source.ravel() < 0] = 0
        return out.reshape(img.shape)


def forward_splat(displacement, frame, eye, present=None):
    """Paint every source texel at its pre-warped position in the occlusion-compatible order (the last painted
    wins): a `Splat`. displacement: (H, W) float orthogonal displacements, row 0 at v = 0; present: (H, W) bool, the
    texels where the object is (None: all)."""
    d = np.asarray(displacement, np.float64)
    h, w = d.shape
    dest, inside = _destinations(w, h, frame, eye, d, present)
    rank = traversal_rank(w, h, frame, eye).ravel()
    best = np.full(w * h, -1, np.int64)
    np.maximum.at(best, dest[inside], rank[inside])
    by_rank = np.empty(w * h, np.int64)
    by_rank[rank] = np.arange(w * h)
    source = np.where(best >= 0, by_rank[np.maximum(best, 0)], -1)
    return Splat(source.reshape(h, w))


def zbuffer_splat(displacement, frame, eye, present=None):
    """The oracle: the same splats, each destination keeping the texel nearest to ``eye`` (a depth buffer)."""
    d = np.asarray(displacement, np.float64)
    h, w = d.shape
    dest, inside = _destinations(w, h, frame, eye, d, present)
    v, u = np.mgrid[0:h, 0:w]
    dist = np.linalg.norm(frame.point(u + 0.5, v + 0.5, d) - np.asarray(eye, np.float64), axis=-1).ravel()
    order = np.lexsort((dist[inside], dest[inside]))  # per destination, nearest first
    src = np.flatnonzero(inside)[order]
    dst = dest[inside][order]
    first = np.r_[True, dst[1:] != dst[:-1]]
    source = np.full(w * h, -1, np.int64)
    source[dst[first]] = src[first]
    return Splat(source.reshape(h, w))


def _fill_rows(source, max_gap=None):
    """Each hole (-1) of each row takes the source of the nearest painted texel in its row (ties: the left one);
    with ``max_gap``, only holes in a run bounded by painted texels on both sides and at most that long (the
    object's outside, reaching the border or wider, stays empty). Rows with nothing painted stay as they are."""
    h, w = source.shape
    idx = np.broadcast_to(np.arange(w), (h, w))
    painted = source >= 0
    left = np.maximum.accumulate(np.where(painted, idx, -1), axis=1)
    right = np.minimum.accumulate(np.where(painted, idx, w)[:, ::-1], axis=1)[:, ::-1]
    use_left = (left >= 0) & ((right >= w) | (idx - left <= right - idx))
    pick = np.where(use_left, left, right)
    ok = (pick >= 0) & (pick < w)
    if max_gap is not None:
        ok &= (left >= 0) & (right < w) & (right - left - 1 <= max_gap)
    filled = np.take_along_axis(source, np.clip(pick, 0, w - 1), axis=1)
    return np.where(painted, source, np.where(ok, filled, -1))


def fill_holes(splat, max_gap=None, passes=4):
    """Two 1-D passes ([Clua et al., correction 7]: the paper leaves the method open): holes take the nearest
    painted texel of their row, then what is left the nearest of its column. ``max_gap`` (texels): fill only runs of
    holes enclosed on both sides and at most that long, so an object's outline stays where it is (None: every hole
    of a row or column with something painted). With ``max_gap`` the two passes repeat while they fill anything, at
    most ``passes`` times: where the eye magnifies the relief (its front seen off the board's axis) the gaps run
    longer than ``max_gap`` both ways, and only the column pass shortens a row's run enough for the next row pass.
    A new `Splat`."""
    source = splat.source
    for _ in range(max(1, passes) if max_gap is not None else 1):
        filled = _fill_rows(_fill_rows(source, max_gap).T, max_gap).T
        if np.array_equal(filled, source):
            break
        source = filled
    return Splat(source)

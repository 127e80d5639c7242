"""When a nailboard must be made again ([Clua et al., §5.1], formulated as its corrections 3-6 say).

- Sprite resolution (eq. 8): ``res = res_screen * size / (2 * distance * tan(FOV / 2))``, rounded up (`ceil`) or
  to the next power of two (`POW2`): 88.68 -> 89 (or 128) for 1024 px, size 1, distance 10, FOV 60°.
- The size of a screen pixel ``b_tela = 2 tan(FOV / 2) / res_screen`` (at unit distance, on the view's centre
  line). The paper's FOV / res is smaller by tan(x) / x: with it a board just made by eq. 8 would already fail
  eq. 9 (by 10% at 60°); this one is eq. 8's own measure, so a new board passes at K = 1.
- Approach (b_transV) and parallax (b_transH): a bounding-box corner P and its image P' on the board's plane seen
  from the viewpoint O1 the board was made for; from the current viewpoint O2 the error is the angle between
  P - O2 and P' - O2. b_transV is the largest error over the box's corners; b_transH the angle, from O2, between
  the two box extremes that were one behind the other from O1 (the nearest and farthest corner along O1's ray to
  the centre): a pure dolly along that ray keeps them in line (b_transH = 0), a strafe separates them.
- Resolution (eq. 9): ``b_nailboard > K * b_tela`` with b_nailboard the board's size over its current distance
  ([Clua et al., correction 3]: what it subtends now, not the camera's FOV), over its resolution: its texels grew larger
  than K screen pixels. The size is the box's diagonal, for eq. 8 and here alike.
- A relief-mapped board corrects most of the parallax, so its parallax test runs on the residual: the report leaves
  it open ([Clua et al., correction 6]), our choice is ``relief_factor`` times the plain board's error (an assumption; K
  and the factor are user parameters, measured by the bench).
"""

from dataclasses import dataclass

import numpy as np

from ..common.errors import InvalidInputError
from ..common.tolerances import ROUND_OFF_SLACK


def sprite_resolution(res_screen, size, distance, fov, rounding="CEIL"):
    """Eq. 8, rounded by ``rounding`` (CEIL or POW2): int. fov in radians."""
    if not (distance > 0 and size > 0 and 0 < fov < np.pi and res_screen > 0):
        raise InvalidInputError("Sprite resolution needs a positive size, distance and resolution, 0 < FOV < 180°")
    res = res_screen * size / (2.0 * distance * np.tan(fov / 2.0))
    n = int(np.ceil(res - ROUND_OFF_SLACK))
    if rounding == "POW2":
        return int(2 ** int(np.ceil(np.log2(max(n, 1)))))
    if rounding != "CEIL":
        raise InvalidInputError(f"rounding must be CEIL or POW2; got {rounding!r}")
    return n


def _angle(a, b):
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    cos = np.einsum("...i,...i->...", a, b) / (np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1))
    return np.arccos(np.clip(cos, -1.0, 1.0))


def box_corners(lo, hi):
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    return np.array([[(hi if (k >> i) & 1 else lo)[i] for i in range(3)] for k in range(8)])


@dataclass(frozen=True)
class Board:
    """A nailboard made from ``eye`` (O1): its plane through the box centre facing O1, the object's box (lo, hi),
    its resolution (texels a side)."""

    eye: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    resolution: int

    @property
    def centre(self):
        return (np.asarray(self.lo, np.float64) + np.asarray(self.hi, np.float64)) / 2

    def on_plane(self, p):
        """Images P' of points (..., 3) on the board's plane seen from O1."""
        o1, c = np.asarray(self.eye, np.float64), self.centre
        n = (c - o1) / np.linalg.norm(c - o1)
        p = np.asarray(p, np.float64)
        t = np.dot(c - o1, n) / np.einsum("...i,i->...", p - o1, n)
        return o1 + t[..., None] * (p - o1)


def errors(board, eye):
    """(b_transV, b_transH) radians of ``board`` seen from ``eye`` (O2)."""
    o2 = np.asarray(eye, np.float64)
    corners = box_corners(board.lo, board.hi)
    v = float(_angle(corners - o2, board.on_plane(corners) - o2).max())
    o1, c = np.asarray(board.eye, np.float64), board.centre
    axis = (c - o1) / np.linalg.norm(c - o1)
    along = (corners - o1) @ axis
    lateral = np.linalg.norm((corners - o1) - along[:, None] * axis, axis=1)
    # the two extremes one behind the other from O1: the corners nearest the O1 -> centre ray, nearest and farthest
    near = corners[np.lexsort((lateral, along))[0]]
    far = corners[np.lexsort((lateral, -along))[0]]
    front, back = o1 + ((near - o1) @ axis) * axis, o1 + ((far - o1) @ axis) * axis  # on the ray itself
    h = float(_angle(front - o2, back - o2))
    return v, h


def texel_size(board, eye):
    """b_nailboard: the board's size (its box's diagonal) over its distance from ``eye``, over its resolution."""
    size = np.linalg.norm(np.asarray(board.hi, np.float64) - np.asarray(board.lo, np.float64))
    return size / np.linalg.norm(np.asarray(eye, np.float64) - board.centre) / board.resolution


@dataclass(frozen=True)
class Verdict:
    approach: bool
    parallax: bool
    resolution: bool

    @property
    def regenerate(self):
        return self.approach or self.parallax or self.resolution


def check(board, eye, fov, res_screen, k=1.0, relief_factor=1.0):
    """Whether ``board`` must be made again for ``eye``: a `Verdict`. b_tela = 2 tan(fov / 2) / res_screen; ``k``:
    eq. 9's tolerance, also applied to the angle tests; ``relief_factor``: the share of the parallax error a
    relief-mapped board still shows, 1 for a plain sprite."""
    if not (k > 0 and 0 < relief_factor <= 1):
        raise InvalidInputError("K must be positive and the relief factor in (0, 1]")
    b_tela = 2.0 * np.tan(fov / 2.0) / res_screen
    v, h = errors(board, eye)
    return Verdict(v * relief_factor > k * b_tela, h * relief_factor > k * b_tela, texel_size(board, eye) > k * b_tela)

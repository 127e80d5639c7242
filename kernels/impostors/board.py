"""Where a nailboard is and how it is rendered ([Clua et al., §5]–B.6): the board's plane, texel axes and resolution
for an object's bounding box seen from an eye, and the orthographic camera that renders its source images.

The board faces the eye (f = unit(eye - centre)); it lies at the back of the box's bounding sphere, so every point of
the object is in front of it (displacements d >= 0 towards the eye, the order `prewarp.traversal_rank` assumes).
Its side is the box's diagonal (the bounding sphere's diameter), its resolution eq. 8 from the camera's, and the
render camera is orthographic, looking down -f from the sphere's front, so a pixel's depth z gives the texel's
displacement d = diameter - z.
"""

from dataclasses import dataclass

import numpy as np

from ..common.errors import InvalidInputError
from .prewarp import ReliefFrame
from .validity import sprite_resolution


@dataclass(frozen=True)
class BoardSetup:
    """frame: the board's `ReliefFrame` (texel axes); resolution: texels a side; size: its side (world);
    camera_location (3,), camera_forward (3,) (= -f), camera_up (3,): the orthographic render camera."""

    frame: ReliefFrame
    resolution: int
    size: float
    camera_location: np.ndarray
    camera_forward: np.ndarray
    camera_up: np.ndarray

    def displacement(self, depth):
        """Displacements d (H, W) from the render's depth (distance from the camera along -f), (H, W)."""
        return self.size - np.asarray(depth, np.float64)


def board_setup(lo, hi, eye, res_screen, fov, rounding="CEIL", max_resolution=2048):
    """The board of a box (lo, hi (3,)) for ``eye``: a `BoardSetup`; resolution eq. 8 (the camera's resolution
    and field of view, radians), at most ``max_resolution``."""
    lo, hi, eye = (np.asarray(x, np.float64) for x in (lo, hi, eye))
    centre = (lo + hi) / 2
    size = float(np.linalg.norm(hi - lo))
    dist = float(np.linalg.norm(eye - centre))
    if size <= 0 or not np.isfinite(size):
        raise InvalidInputError("The object has no extent to make a board of")
    if dist <= size / 2:
        raise InvalidInputError("The eye is inside the object's bounding sphere: no board can stand between")
    res = min(sprite_resolution(res_screen, size, dist, fov, rounding), int(max_resolution))
    f = (eye - centre) / dist
    helper = np.array([0.0, 0.0, 1.0]) if abs(f[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    a_dir = np.cross(helper, f)
    a_dir /= np.linalg.norm(a_dir)
    b_dir = np.cross(f, a_dir)
    texel = size / res
    back = centre - f * size / 2
    origin = back - (a_dir + b_dir) * size / 2
    frame = ReliefFrame(origin, a_dir * texel, b_dir * texel, f)
    return BoardSetup(frame, res, size, centre + f * size / 2, -f, b_dir)

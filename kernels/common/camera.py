"""Cameras as numpy arrays (row-major matrices, OpenGL clip-space conventions, eye looking down -z).

`product` and `Camera.eye` use only elementwise +, -, × and / in a fixed order, never BLAS or LAPACK (whose rounding
depends on the CPU and the library's build): a camera gives the same bits on every machine, so view-dependent levels
computed by separate farm tasks on different machines agree (terrain blocks weld exactly).
"""

from dataclasses import dataclass

import numpy as np

from .errors import InvalidInputError
from .tolerances import NO_DIRECTION


def product(a, b):
    """``a @ b`` for (4, 4) matrices, each entry summed in the order k = 0, 1, 2, 3 with separate roundings (the same
    bits on every machine): (4, 4) float64."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    return ((a[:, 0, None] * b[0] + a[:, 1, None] * b[1]) + a[:, 2, None] * b[2]) + a[:, 3, None] * b[3]


def _affine_eye(view):
    """Where an affine world -> eye matrix puts the eye: ``-A⁻¹ t`` by the adjugate (fixed order): (3,) float64."""
    (a, b, c), (d, e, f), (g, h, i) = view[:3, :3]
    t = view[:3, 3]
    cof = np.array([[e * i - f * h, c * h - b * i, b * f - c * e],
                    [f * g - d * i, a * i - c * g, c * d - a * f],
                    [d * h - e * g, b * g - a * h, a * e - b * d]])
    det = (a * cof[0, 0] + b * cof[1, 0]) + c * cof[2, 0]
    return -(((cof[:, 0] * t[0] + cof[:, 1] * t[1]) + cof[:, 2] * t[2]) / det)


def perspective(fovy, aspect, near, far):
    """OpenGL perspective projection: vertical field of view in radians -> (4, 4) float64."""
    t = 1.0 / np.tan(fovy / 2.0)
    proj = np.zeros((4, 4))
    proj[0, 0], proj[1, 1] = t / aspect, t
    proj[2, 2], proj[2, 3] = (far + near) / (near - far), 2.0 * far * near / (near - far)
    proj[3, 2] = -1.0
    return proj


def look_at_view(eye, target, up=(0.0, 0.0, 1.0)):
    """World -> eye matrix (4, 4) float64 for a camera at ``eye`` looking at ``target``."""
    eye, target, up = (np.asarray(v, np.float64) for v in (eye, target, up))
    f = target - eye
    f /= np.linalg.norm(f)
    s = np.cross(f, up)
    if np.linalg.norm(s) < NO_DIRECTION:
        s = np.cross(f, (0.0, 1.0, 0.0))
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = s, u, -f
    view[:3, 3] = -view[:3, :3] @ eye
    return view


def look_at(eye, target, up=(0.0, 0.0, 1.0), fov_deg=40.0, aspect=1.0, near=0.05, far=100.0):
    """Perspective view-projection matrix (4, 4) float64, row-major, OpenGL clip conventions."""
    return perspective(np.radians(fov_deg), aspect, near, far) @ look_at_view(eye, target, up)


@dataclass(frozen=True)
class Camera:
    """What view-dependent metrics need: view (4, 4) world -> eye, projection (4, 4), viewport size in pixels."""

    view: np.ndarray
    projection: np.ndarray
    width: int
    height: int

    def __post_init__(self):
        for name in ("view", "projection"):
            m = np.asarray(getattr(self, name), np.float64)
            if m.shape != (4, 4) or not np.all(np.isfinite(m)):
                raise InvalidInputError(f"The camera's {name} matrix must be a finite 4x4 matrix")
        if self.width < 1 or self.height < 1:
            raise InvalidInputError("The camera's viewport must be at least one pixel wide and high")

    @property
    def orthographic(self):
        return bool(np.asarray(self.projection)[3, 3] == 1.0)

    @property
    def clip_end(self):
        """Distance to the far clipping plane, from the projection (OpenGL convention): float."""
        p = np.asarray(self.projection, np.float64)
        if self.orthographic:
            return float((p[2, 3] - 1.0) / p[2, 2])
        return float(p[2, 3] / (p[2, 2] + 1.0))

    @property
    def eye(self):
        """Camera position in world space: (3,) float64 (the same bits on every machine for an affine view)."""
        view = np.asarray(self.view, np.float64)
        if np.array_equal(view[3], (0.0, 0.0, 0.0, 1.0)):
            return _affine_eye(view)
        return np.linalg.inv(view)[:3, 3]

    @property
    def backward(self):
        """Unit world vector from the scene toward the camera (the eye's +z axis): (3,) float64."""
        v = np.linalg.inv(np.asarray(self.view, np.float64))[:3, 2]
        return v / np.linalg.norm(v)

    @classmethod
    def looking_at(cls, eye, target, fov_deg=40.0, width=640, height=480, near=0.05, far=1000.0, up=(0, 0, 1)):
        return cls(look_at_view(eye, target, up), perspective(np.radians(fov_deg), width / height, near, far),
                   width, height)

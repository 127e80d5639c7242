"""Camera matrices as numpy arrays (row-major, OpenGL clip-space conventions)."""

import numpy as np


def look_at(eye, target, up=(0.0, 0.0, 1.0), fov_deg=40.0, aspect=1.0, near=0.05, far=100.0):
    """Perspective view-projection matrix (4, 4) float64, row-major, OpenGL clip conventions."""
    eye, target, up = (np.asarray(v, np.float64) for v in (eye, target, up))
    f = target - eye
    f /= np.linalg.norm(f)
    s = np.cross(f, up)
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = s, u, -f
    view[:3, 3] = -view[:3, :3] @ eye
    t = 1.0 / np.tan(np.radians(fov_deg) / 2.0)
    proj = np.zeros((4, 4))
    proj[0, 0], proj[1, 1] = t / aspect, t
    proj[2, 2], proj[2, 3] = (far + near) / (near - far), 2.0 * far * near / (near - far)
    proj[3, 2] = -1.0
    return proj @ view

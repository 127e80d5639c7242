"""Where a live one-point surface's instances are: its control points (the object's origin, or the vertices of its
Control Points mesh) and their factors. Shared by the viewport preview and Bake Surface."""

import numpy as np

from ...kernels.common.errors import InvalidInputError
from ...kernels.surfaces.domain_mesh import camera_factors
from ..bridge import read_wire_mesh
from .settings import surface_from


def control_points(ob):
    """The control points of a live surface ``ob`` in its own space: (N, 3) float64."""
    src = ob.tessera.surface.instance_object
    if src is None:
        return np.zeros((1, 3))
    if src.type != "MESH":
        raise InvalidInputError(f"Control Points must be a mesh object; {src.name!r} is a {src.type.lower()}")
    pos, _ = read_wire_mesh(src.data)
    if len(pos) == 0:
        raise InvalidInputError(f"{src.name!r} has no vertices to put surfaces on")
    to_local = np.linalg.inv(np.array(ob.matrix_world)) @ np.array(src.matrix_world)
    return pos.astype(np.float64) @ to_local[:3, :3].T + to_local[:3, 3]


def instance_factors(ob, points, camera=None):
    """One factor per control point: the fixed Factor, or from ``camera`` (object space) with Factor From Camera."""
    s = ob.tessera.surface
    if s.factor_mode == "CAMERA" and camera is not None:
        return camera_factors(surface_from(s), points, camera, s.edge_pixels)
    return np.full(len(points), s.factor, np.int64)

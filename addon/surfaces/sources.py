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
    bad = ~np.isfinite(pos).all(axis=1)
    if bad.any():
        raise InvalidInputError(f"Vertex {int(np.argmax(bad))} of the Control Points {src.name!r} is at NaN or "
                                "infinity: move or delete it")
    world = np.array(ob.matrix_world)
    if not abs(np.linalg.det(world[:3, :3])) > 1e-30:
        raise InvalidInputError(f"{ob.name!r} is scaled to zero (or flattened): its control points cannot be "
                                "placed on it. Give it a scale")
    to_local = np.linalg.inv(world) @ np.array(src.matrix_world)
    return pos.astype(np.float64) @ to_local[:3, :3].T + to_local[:3, 3]


def instance_factors(ob, points, camera=None):
    """One factor per control point: the fixed Factor, or from ``camera`` (object space) with Factor From Camera."""
    s = ob.tessera.surface
    if s.factor_mode == "CAMERA" and camera is not None:
        return camera_factors(surface_from(s), points, camera, s.edge_pixels)
    return np.full(len(points), s.factor, np.int64)

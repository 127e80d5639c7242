"""Cameras from Blender (the scene camera, or the active 3D viewport) as `kernels.common.camera.Camera`."""

import numpy as np

from ..kernels.common.camera import Camera, product
from ..kernels.common.errors import InvalidInputError

#: The camera choice of every view-dependent setting (adaptive levels, tube sides, the pixel clamp).
CAMERA_ITEMS = (
    ("SCENE", "Scene Camera", "The scene camera at the render resolution (render and export)"),
    ("VIEWPORT", "Viewport", "The active 3D viewport"),
)


def scene_camera(context, purpose="Adaptive levels"):
    """The scene camera at the render resolution. Raises `InvalidInputError` when the scene has none; the message
    names ``purpose`` (what needs the camera)."""
    scene = context.scene
    ob = scene.camera
    if ob is None:
        raise InvalidInputError(f"{purpose}: the scene has no camera; set the scene camera, or use the viewport")
    render = scene.render
    width = max(1, round(render.resolution_x * render.resolution_percentage / 100))
    height = max(1, round(render.resolution_y * render.resolution_percentage / 100))
    projection = ob.calc_matrix_camera(context.evaluated_depsgraph_get(), x=width, y=height,
                                       scale_x=render.pixel_aspect_x, scale_y=render.pixel_aspect_y)
    return Camera(np.array(ob.matrix_world.inverted()), np.array(projection), width, height)


def viewport_camera(context):
    """The active 3D viewport's view. Raises `InvalidInputError` outside a 3D viewport (e.g. in background)."""
    region, rv3d = context.region, context.region_data
    if region is None or rv3d is None or not hasattr(rv3d, "view_matrix"):
        raise InvalidInputError("No 3D viewport here: run from a 3D viewport, or use the scene camera")
    return Camera(np.array(rv3d.view_matrix), np.array(rv3d.window_matrix), region.width, region.height)


def camera_for(context, source, purpose="Adaptive levels"):
    """``source``: ``"SCENE"`` or ``"VIEWPORT"``; ``purpose`` names what needs it, for the message."""
    return viewport_camera(context) if source == "VIEWPORT" else scene_camera(context, purpose)


def object_camera(camera, matrix_world):
    """``camera`` seen from an object's local space (for work done in object coordinates)."""
    m = np.array(matrix_world, np.float64)
    return Camera(product(camera.view, m), camera.projection, camera.width, camera.height)

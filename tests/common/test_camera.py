"""`kernels.common.camera.Camera`: what the projection says about the view."""

import numpy as np
import pytest
from tessera.kernels.common.camera import Camera, look_at_view


@pytest.mark.parametrize("far", [0.5, 100.0, 3.6e4])
def test_clip_end_is_read_back_from_perspective_and_orthographic_projections(far):
    cam = Camera.looking_at((0.0, -5.0, 1.0), (0.0, 0.0, 0.0), near=0.01, far=far)
    assert cam.clip_end == pytest.approx(far, rel=1e-9)
    near = 0.1
    ortho = np.diag([0.5, 0.5, -2.0 / (far - near), 1.0])
    ortho[2, 3] = -(far + near) / (far - near)
    cam = Camera(look_at_view((0.0, -5.0, 1.0), (0.0, 0.0, 0.0), (0, 0, 1)), ortho, 64, 64)
    assert cam.orthographic and cam.clip_end == pytest.approx(far, rel=1e-9)

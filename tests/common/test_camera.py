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


def test_the_eye_and_products_are_computed_without_blas_or_lapack(monkeypatch):
    """Farm tasks on different machines must agree bit for bit: the eye comes from the adjugate and 4x4 products from
    elementwise operations in a fixed order, never from LAPACK or BLAS (whose rounding depends on the CPU). Their
    values are those of the library routines to rounding."""
    from tessera.kernels.common.camera import product

    rng = np.random.default_rng(4)
    view = look_at_view(rng.normal(size=3) * 30, rng.normal(size=3), (0, 0, 1))
    scale = np.diag([2.0, 0.5, 3.0, 1.0])
    scale[:3, 3] = rng.normal(size=3)
    want_eye = np.linalg.inv(product(view, scale))[:3, 3]
    want = view @ scale
    monkeypatch.setattr(np.linalg, "inv", None)  # any use would raise
    cam = Camera(product(view, scale), np.eye(4), 8, 8)
    assert cam.eye == pytest.approx(want_eye, rel=1e-12, abs=1e-12)
    assert product(view, scale) == pytest.approx(want, rel=1e-14, abs=1e-14)
    a, b = rng.normal(size=(4, 4)), rng.normal(size=(4, 4))
    p = product(a, b)
    assert p[2, 1] == ((a[2, 0] * b[0, 1] + a[2, 1] * b[1, 1]) + a[2, 2] * b[2, 1]) + a[2, 3] * b[3, 1]  # its order

"""When a nailboard is made again ([Clua et al., §5.1]): eq. 8, and the approach, parallax
and resolution tests on scripted camera paths."""

import numpy as np
import pytest
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.impostors import validity as va

FOV, RES = np.radians(60), 1024


def test_eq_8_and_its_rounding():
    assert 1024 / (2 * 10 * np.tan(np.radians(30))) == pytest.approx(88.68, abs=0.01)
    assert va.sprite_resolution(1024, 1.0, 10.0, np.radians(60)) == 89
    assert va.sprite_resolution(1024, 1.0, 10.0, np.radians(60), "POW2") == 128
    with pytest.raises(InvalidInputError):
        va.sprite_resolution(1024, 1.0, 0.0, FOV)


def board_from(eye):
    res = va.sprite_resolution(RES, 2.0 * np.sqrt(3.0), np.linalg.norm(eye), FOV)  # size: the box's diagonal
    return va.Board(np.asarray(eye, float), np.array([-1.0, -1, -1]), np.array([1.0, 1, 1]), res)


def test_a_static_camera_never_regenerates():
    b = board_from((0, -10, 0))
    v, h = va.errors(b, (0, -10, 0))
    assert v == pytest.approx(0, abs=1e-12) and h == pytest.approx(0, abs=1e-12)
    assert not va.check(b, (0, -10, 0), FOV, RES).regenerate


def test_a_dolly_triggers_approach_and_resolution_only():
    b = board_from((0, -10, 0))
    hits = []
    for y in np.linspace(-10, -2.5, 40):
        verdict = va.check(b, (0, y, 0), FOV, RES)
        assert not verdict.parallax  # the extremes stay in line along the ray
        hits.append(verdict.regenerate)
    assert not hits[0] and hits[-1]
    assert va.errors(b, (0, -6, 0))[1] == pytest.approx(0, abs=1e-9)


def test_a_strafe_triggers_parallax():
    b = board_from((0, -10, 0))
    first = None
    for k, x in enumerate(np.linspace(0, 3, 60)):
        verdict = va.check(b, (x, -10, 0), FOV, RES)
        if verdict.parallax:
            first = k
            break
    assert first is not None and first > 0
    # a relief-mapped board, whose residual parallax is smaller, lasts longer on the same path
    later = next(k for k, x in enumerate(np.linspace(0, 3, 60)) if va.check(b, (x, -10, 0), FOV, RES,
                                                                             relief_factor=0.25).parallax)
    assert later > first

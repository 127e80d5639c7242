"""Strokes on displacement maps: spacing, pressure, X-mirror, deterministic replay and exact tile undo."""

import numpy as np
import pytest
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.displacement.map_strokes import TILE, Brush, TileUndo, run_stroke, stroke_dabs


def test_dabs_are_evenly_spaced_with_interpolated_pressure():
    dabs = stroke_dabs([(0, 0, 0.0), (10, 0, 1.0), (10, 10, 1.0)], 2.5)
    assert len(dabs) == 9  # arc length 20 -> dabs at 0, 2.5, ..., 20
    steps = np.hypot(*np.diff(dabs[:, :2], axis=0).T)
    assert np.allclose(steps[:3], 2.5) and np.isclose(dabs[2, 2], 0.5)
    assert np.array_equal(stroke_dabs([(3, 4, 0.5)], 1.0), [[3, 4, 0.5]])
    with pytest.raises(InvalidInputError):
        stroke_dabs([(0, 0, 2.0), (1, 1, 0.5)], 1.0)


def test_replay_is_deterministic_and_undo_restores_exact_bytes():
    rng = np.random.default_rng(3)
    base = rng.normal(size=(200, 300, 1)).astype(np.float32)
    t = np.linspace(0, 3, 40)
    path = np.column_stack([20 + 80 * t, 100 + 60 * np.sin(t), np.linspace(0.2, 1, 40)])
    runs = []
    for _ in range(2):
        m = base.copy()
        undo = TileUndo(m)
        for kind in ("DRAW", "SMOOTH", "NOISE"):
            run_stroke(m, Brush(kind=kind, radius=12, strength=0.3, params={"cell": 5.0}), path, backend="numpy",
                       undo=undo)
        undo.close(m)
        runs.append((m, undo))
    (a, undo), (b, _) = runs
    assert np.array_equal(a, b)
    edited = a.copy()
    undo.undo(a)
    assert a.tobytes() == base.tobytes()
    undo.redo(a)
    assert a.tobytes() == edited.tobytes()
    touched = len(undo.before)
    assert touched < (200 // TILE + 1) * (300 // TILE + 1)  # only the tiles under the stroke
    assert undo.nbytes == 2 * sum(t.nbytes for t in undo.before.values())


def test_x_mirror_paints_the_mirror_image():
    m = np.zeros((64, 101, 1), np.float32)
    run_stroke(m, Brush(kind="DRAW", radius=6, strength=0.5, mirror_x=True), [(20, 10, 1), (30, 40, 1)],
               backend="numpy")
    assert m.any() and np.allclose(m, m[:, ::-1], rtol=0, atol=4e-6)  # up to the rounding of mirrored positions
    v = np.zeros((64, 101, 3), np.float32)
    run_stroke(v, Brush(kind="DRAW", radius=6, strength=0.5, mirror_x=True, params={"vector": (1, 0, 1, 0)}),
               [(20, 30, 1)], backend="numpy")
    assert np.allclose(v[..., 0], -v[:, ::-1, 0], atol=1e-6) and np.allclose(v[..., 2], v[:, ::-1, 2], atol=1e-6)
    assert v[..., 0].min() < -0.4 and v[..., 0].max() > 0.4


def test_pressure_scales_strength_and_optionally_radius():
    a = np.zeros((64, 64, 1), np.float32)
    run_stroke(a, Brush(kind="DRAW", radius=10, strength=1.0, params={"falloff": "CONSTANT"}), [(32, 32, 0.25)],
               backend="numpy")
    assert np.isclose(a.max(), 0.25)
    b = np.zeros((64, 64, 1), np.float32)
    run_stroke(b, Brush(kind="DRAW", radius=10, strength=1.0, pressure_radius=True, params={"falloff": "CONSTANT"}),
               [(32, 32, 0.5)], backend="numpy")
    assert np.count_nonzero(b) == np.count_nonzero(np.hypot(*np.mgrid[-32:32, -32:32]) < 5)


def test_a_failing_dab_changes_nothing_of_its_own():
    m = np.zeros((32, 32, 1), np.float32)
    m[16, 16] = np.nan
    before = m.copy()
    with pytest.raises(InvalidInputError):
        run_stroke(m, Brush(kind="DRAW", radius=4), [(16, 16, 1)], backend="numpy", undo=TileUndo(m))
    assert np.array_equal(m, before, equal_nan=True)


def test_a_brush_with_an_unknown_parameter_is_refused_before_any_dab():
    m = np.zeros((32, 32, 1), np.float32)
    with pytest.raises(InvalidInputError, match="celll"):
        run_stroke(m, Brush(kind="NOISE", radius=4, params={"celll": 5.0}), [(5, 5, 1.0), (20, 20, 1.0)],
                   backend="numpy")
    assert not m.any()

"""Displacement-map kernels, numpy reference ([Andrade 2012]'s test values; kernels.displacement.map_dabs /
map_edit)."""

import numpy as np
import pytest
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.displacement.map_edit import apply_dab, morph


def zero_map(channels=4, size=64):
    return np.zeros((size, size, channels), np.float32)


@pytest.mark.parametrize("radius, count", [(1, 1), (2, 9), (3, 25), (5, 69), (10, 305), (16, 793)])
def test_contact_footprint_counts(radius, count):
    m = zero_map()
    apply_dab(m, "CONTACT", backend="numpy", pos=(32, 32), depth=0.1, radius=radius)
    assert np.count_nonzero(m[..., 2]) == count


def test_contact_changes_z_only_and_accumulates_exactly():
    m = zero_map()
    for _ in range(10):
        apply_dab(m, "CONTACT", backend="numpy", pos=(32, 32), depth=0.1, radius=5)
    assert np.count_nonzero(m[..., 2]) == 69
    assert m[32, 37, 2] == 0  # distance exactly 5: outside the open disc
    assert np.all(m[..., [0, 1, 3]] == 0)
    assert np.allclose(m[32, 32, 2], -1.0, atol=1e-6)
    one = zero_map(1)
    apply_dab(one, "CONTACT", backend="numpy", pos=(32, 32), depth=0.25, radius=5)
    assert np.count_nonzero(one) == 69 and one.min() == np.float32(-0.25)  # height maps: the one channel


def test_force_seed_example():
    m = zero_map()
    apply_dab(m, "FORCE", backend="numpy", pos=(32, 32), force=(0, 0, -0.5, 10))
    assert tuple(m[32, 32]) == (0, 0, np.float32(-0.5), 10)
    assert m[32, 35, 2] == np.float32(-0.2) and m[32, 35, 3] == np.float32(4)
    assert m[32, 36, 2] == np.float32(-0.1) and m[32, 36, 3] == np.float32(2)
    assert np.all(m[36, 35] == 0) and np.all(m[32, 37] == 0)  # distance exactly 5
    assert np.count_nonzero(m[..., 2]) == 69


@pytest.mark.parametrize("f", [(0, 0, -0.5, 0), (0, 0, 0, 10), (0, 0, -0.5, -2), (0, 0, np.nan, 1)])
def test_degenerate_forces_are_refused_and_change_nothing(f):
    m = np.random.default_rng(0).normal(size=(32, 32, 4)).astype(np.float32)
    before = m.copy()
    with pytest.raises(InvalidInputError):
        apply_dab(m, "FORCE", backend="numpy", pos=(10, 10), force=f)
    assert np.array_equal(m, before)


def test_nan_under_the_brush_is_refused_and_changes_nothing():
    m = zero_map()
    m[30, 30, 0] = np.nan
    before = m.copy()
    with pytest.raises(InvalidInputError, match="NaN"):
        apply_dab(m, "DRAW", backend="numpy", pos=(31, 31), radius=4, strength=0.5)
    assert np.array_equal(m, before, equal_nan=True)
    with pytest.raises(InvalidInputError, match="finite"):
        apply_dab(zero_map(), "CONTACT", backend="numpy", pos=(np.nan, 3), depth=1, radius=2)


def test_test_kernel_seed_example():
    m = zero_map()
    apply_dab(m, "TEST", backend="numpy", arg1=(10, 10, 0, 0), arg2=(0, 0, 0.25, 0), arg3=(3, 0, 0, 0))
    assert np.count_nonzero(m) == 25 and np.all(m[m != 0] == np.float32(0.25))


def test_morphing_ends_and_middle():
    rng = np.random.default_rng(1)
    a = rng.normal(size=(16, 16, 3)).astype(np.float32)
    b = rng.normal(size=(16, 16, 3)).astype(np.float32)
    a0, b0 = a.copy(), b.copy()
    assert np.array_equal(morph(a, b, 0.0, backend="numpy"), a)
    assert np.array_equal(morph(a, b, 1.0, backend="numpy"), b)
    mid = morph(a, b, 0.5, backend="numpy")
    assert np.allclose(mid, (a + b) / 2, atol=1e-6)
    assert np.array_equal(a, a0) and np.array_equal(b, b0)


@pytest.mark.parametrize("falloff", ["SMOOTH", "SPHERE", "LINEAR", "SHARP", "CONSTANT"])
def test_draw_falloff_peaks_at_the_centre_and_vanishes_at_the_rim(falloff):
    m = zero_map(1, 65)
    apply_dab(m, "DRAW", backend="numpy", pos=(32, 32), radius=20, strength=0.5, falloff=falloff)
    profile = m[32, 32:53, 0]
    assert profile[0] == np.float32(0.5)
    assert np.all(np.diff(profile[:20]) <= 0) and profile[20] == 0  # monotone, zero at d = r
    if falloff == "CONSTANT":
        assert np.count_nonzero(m) == np.count_nonzero(np.hypot(*np.meshgrid(np.arange(65) - 32.0,
                                                                             np.arange(65) - 32.0)) < 20)


def test_smooth_and_flatten_reduce_roughness_inside_only():
    rng = np.random.default_rng(2)
    m = rng.normal(size=(64, 64, 1)).astype(np.float32)
    before = m.copy()
    region = apply_dab(m, "SMOOTH", backend="numpy", pos=(20, 20), radius=8, strength=1.0, falloff="CONSTANT")
    x0, y0, x1, y1 = region
    outside = np.ones((64, 64), bool)
    outside[y0:y1, x0:x1] = False
    assert np.array_equal(m[outside], before[outside])
    core = (slice(16, 25), slice(16, 25))
    assert m[core].std() < 0.5 * before[core].std()
    f = before.copy()
    apply_dab(f, "FLATTEN", backend="numpy", pos=(40, 40), radius=6, strength=1.0, falloff="CONSTANT")
    d = np.hypot(*np.meshgrid(np.arange(64) - 40.0, np.arange(64) - 40.0))
    inside = d < 6
    assert np.allclose(f[inside, 0], before[inside, 0].mean(), atol=1e-5)  # exactly onto the mean plane


def test_stamp_places_a_rotated_decal():
    st = np.zeros((5, 9, 1), np.float32)
    st[2, :, 0] = 1.0  # a horizontal bar, 9 texels long
    m = zero_map(1)
    apply_dab(m, "STAMP", backend="numpy", stamp=st, pos=(32, 32), angle=np.pi / 2, scale=2.0, strength=0.5)
    ys, xs = np.nonzero(m[..., 0] > 0.25)
    assert np.ptp(ys) >= 14 and np.ptp(xs) <= 2  # rotated by 90 degrees and scaled by 2: a vertical bar
    assert np.isclose(m.max(), 0.5)


def test_a_dab_off_the_map_does_nothing():
    m = zero_map()
    assert apply_dab(m, "CONTACT", backend="numpy", pos=(-50, -50), depth=1, radius=5) is None
    assert not m.any()


def test_noise_is_bounded_map_anchored_and_seeded():
    a, b = zero_map(1, 64), zero_map(1, 64)
    apply_dab(a, "NOISE", backend="numpy", pos=(30, 30), radius=12, strength=0.5, falloff="CONSTANT", cell=4, seed=7)
    assert np.abs(a).max() <= 0.5 and np.count_nonzero(a) > 300
    apply_dab(b, "NOISE", backend="numpy", pos=(34, 31), radius=12, strength=0.5, falloff="CONSTANT", cell=4, seed=7)
    both = (a != 0) & (b != 0)
    assert both.sum() > 200 and np.array_equal(a[both], b[both])  # the same texel gets the same noise value
    c = zero_map(1, 64)
    apply_dab(c, "NOISE", backend="numpy", pos=(30, 30), radius=12, strength=0.5, falloff="CONSTANT", cell=4, seed=8)
    assert not np.array_equal(a, c)


def test_dab_parameters_are_a_record_and_bad_names_are_refused():
    """Keywords and a `DabParams` give the same dab; an unknown or missing parameter is an `InvalidInputError`
    naming it, with the map unchanged."""
    from tessera.kernels.displacement.map_edit import DabParams

    a, b = zero_map(), zero_map()
    apply_dab(a, "DRAW", backend="numpy", pos=(20, 30), radius=6, strength=0.5, falloff="LINEAR")
    apply_dab(b, "DRAW", backend="numpy", dab=DabParams(pos=(20, 30), radius=6, strength=0.5, falloff="LINEAR"))
    assert a.any() and np.array_equal(a, b)
    m = zero_map()
    with pytest.raises(InvalidInputError, match="radiuss"):
        apply_dab(m, "DRAW", backend="numpy", pos=(20, 30), radiuss=6)
    with pytest.raises(InvalidInputError, match="'depth'"):
        apply_dab(m, "CONTACT", backend="numpy", pos=(20, 30), radius=6)
    with pytest.raises(InvalidInputError, match="not both"):
        apply_dab(m, "DRAW", backend="numpy", dab=DabParams(pos=(1, 1), radius=2), strength=1.0)
    assert not m.any()


@pytest.mark.parametrize("kind, params", [
    ("DRAW", {"pos": (20, 20), "radius": 8, "strength": 3e38, "vector": (0, 0, 3e38, 0), "falloff": "CONSTANT"}),
    ("NOISE", {"pos": (20, 20), "radius": 8, "strength": 3e38, "vector": (3e38, 3e38, 3e38, 0), "cell": 2.0}),
    ("CONTACT", {"pos": (20, 20), "radius": 8, "depth": -3e38}),
])
def test_a_dab_that_would_overflow_is_refused_with_the_map_unchanged(kind, params):
    """Finite parameters can still overflow float32: the result is computed aside and refused, not committed."""
    m = np.full((40, 40, 4), 3e38, np.float32)
    before = m.copy()
    with pytest.raises(InvalidInputError, match="NaN or infinite"):
        apply_dab(m, kind, backend="numpy", **params)
    assert m.tobytes() == before.tobytes()


def test_pressure_outside_the_unit_range_is_refused():
    m = zero_map()
    for pressure in (5.0, -0.5):
        with pytest.raises(InvalidInputError, match=r"Pressure must lie in \[0, 1\]"):
            apply_dab(m, "DRAW", backend="numpy", pos=(20, 20), radius=5, strength=1.0, pressure=pressure)
    assert not m.any()
    apply_dab(m, "DRAW", backend="numpy", pos=(20, 20), radius=5, strength=1.0, pressure=0.5)
    assert m.any()

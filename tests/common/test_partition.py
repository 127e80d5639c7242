import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.common.partition import clamp_levels, point_params, segment_counts


def params(level, spacing):
    f = clamp_levels([level], spacing)
    n = int(segment_counts(f, spacing)[0])
    return point_params(np.full(n + 1, f[0]), np.full(n + 1, n), np.arange(n + 1), spacing)


@pytest.mark.parametrize(
    "level, spacing, n",
    [(1, "EQUAL", 1), (3.2, "EQUAL", 4), (4, "EQUAL", 4), (100, "EQUAL", 64), (0.2, "EQUAL", 1),
     (1, "FRACTIONAL_EVEN", 2), (3, "FRACTIONAL_EVEN", 4), (4, "FRACTIONAL_EVEN", 4),
     (4.5, "FRACTIONAL_EVEN", 6), (63.1, "FRACTIONAL_EVEN", 64), (100, "FRACTIONAL_EVEN", 64)],
)
def test_rounding_rules(level, spacing, n):
    # [Nellmedin 2014, §2.3.4], [Khronos]: equal rounds up in [1, 64]; even clamps to [2, 64], rounds up to even.
    assert segment_counts([level], spacing)[0] == n


def test_equal_params_are_equal_segments():
    assert np.allclose(np.diff(params(5, "EQUAL")), 0.2, atol=1e-15)


@pytest.mark.parametrize(
    "level, lengths",
    [(3.0, [0.125, 0.125, 0.375, 0.375]), (3.5, [0.1875, 0.1875, 0.3125, 0.3125]),
     (4.5, [0.5 / 12, 0.5 / 12] + [(1 - 1 / 12) / 4] * 4), (1.0, [0.5, 0.5])],
)
def test_fractional_segment_lengths_match_llvmpipe(level, lengths):
    # [Nellmedin 2014, §2.3.4]: the multiset of segment lengths llvmpipe produces (positions differ by vendor).
    assert np.allclose(np.sort(np.diff(params(level, "FRACTIONAL_EVEN"))), np.sort(lengths), atol=1e-12)


@given(st.floats(1.0, 64.0), st.sampled_from(["EQUAL", "FRACTIONAL_EVEN"]))
def test_params_are_a_monotone_palindrome(level, spacing):
    t = params(level, spacing)
    assert t[0] == 0.0 and t[-1] == 1.0
    assert np.all(np.diff(t) >= 0)
    assert np.allclose(t + t[::-1], 1.0, atol=1e-15)


@given(st.integers(1, 31))
def test_fractional_is_continuous_at_both_ends(half):
    n = 2 * half + 2
    # Approaching n from below gives n equal segments; just above n - 2 the two short segments vanish.
    assert np.allclose(params(n - 1e-9, "FRACTIONAL_EVEN"), np.arange(n + 1) / n, atol=1e-8)
    below = params(n - 2 + 1e-9, "FRACTIONAL_EVEN")
    lengths = np.diff(below)
    assert np.sum(lengths < 1e-8) == 2
    assert np.allclose(np.unique(np.round(lengths[lengths > 1e-8], 9)), 1 / (n - 2))


def test_nan_level_is_rejected():
    with pytest.raises(InvalidInputError, match="finite"):
        segment_counts([np.nan])
    with pytest.raises(InvalidInputError, match="spacing"):
        segment_counts([2.0], "FRACTIONAL_ODD")

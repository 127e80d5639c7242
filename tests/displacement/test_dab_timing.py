"""The measured choice of side (host numpy or OpenCL device) for the dabs of a device-resident map."""

import numpy as np
from tessera.kernels.displacement.dab_timing import (
    DEVICE,
    FIRST_RECHECK,
    HOST,
    MIN_SAMPLES,
    RECHECK,
    SWITCH_MARGIN,
    WINDOW,
    DabTimes,
    size_class,
)


def _run(times, kind, texels, cost, n):
    """``n`` dabs chosen by ``times`` with made-up costs ``cost[side]``: the sides taken, in order."""
    sides = []
    for _ in range(n):
        side = times.choose(kind, texels)
        times.record(kind, texels, side, cost[side])
        sides.append(side)
    return sides


def test_size_classes_are_powers_of_two():
    assert [size_class(n) for n in (0, 1, 2, 3, 4, 7, 8, 1023, 1024)] == [1, 1, 2, 2, 3, 3, 4, 10, 11]


def test_a_new_class_starts_on_the_prior_side_and_tries_the_other():
    times = DabTimes(prior_host_texels=1000)
    small = _run(times, "DRAW", 500, {HOST: 1.0, DEVICE: 2.0}, 2 * MIN_SAMPLES)
    large = _run(times, "DRAW", 5000, {HOST: 2.0, DEVICE: 1.0}, 2 * MIN_SAMPLES)
    assert small == [HOST, DEVICE] * MIN_SAMPLES
    assert large == [DEVICE, HOST] * MIN_SAMPLES


def test_the_faster_side_runs_and_the_slower_is_rechecked_ever_more_rarely():
    """The slower side (three times slower here) runs again once the faster has run for FIRST_RECHECK of its dab
    times, then for twice as long after each recheck, up to RECHECK of them."""
    times = DabTimes(prior_host_texels=1000)
    sides = _run(times, "SMOOTH", 500, {HOST: 3.0, DEVICE: 1.0}, 2 * MIN_SAMPLES + 8 * 3 * RECHECK)
    steady = sides[2 * MIN_SAMPLES:]
    rechecks = [i for i, side in enumerate(steady) if side == HOST]
    gaps = np.diff([-1, *rechecks]) - 1  # device dabs before each recheck
    spans = [min(FIRST_RECHECK * 2 ** i, RECHECK) for i in range(len(gaps))]
    assert list(gaps) == [3 * span for span in spans]
    assert spans[-1] == RECHECK and len(gaps) >= 8


def test_a_verdict_from_a_slow_first_trial_is_soon_revised():
    """The device's trials were slow (a kernel built for a new footprint size): the host runs first, the device is
    rechecked after FIRST_RECHECK of its trial times, found faster, and runs from then on."""
    times = DabTimes(prior_host_texels=1000)
    for seconds in (50.0, 45.0):
        times.record("DRAW", 5000, DEVICE, seconds)
    for seconds in (3.0, 3.0):
        times.record("DRAW", 5000, HOST, seconds)
    sides = _run(times, "DRAW", 5000, {HOST: 3.0, DEVICE: 1.0}, 200)
    first = sides.index(DEVICE)
    assert first == FIRST_RECHECK * 45 // 3
    assert sides[first:].count(HOST) <= 4  # the host is rechecked ever more rarely after


def test_kinds_and_classes_keep_their_own_times():
    times = DabTimes(prior_host_texels=1000)
    _run(times, "DRAW", 500, {HOST: 1.0, DEVICE: 2.0}, 2 * MIN_SAMPLES)
    _run(times, "SMOOTH", 500, {HOST: 2.0, DEVICE: 1.0}, 2 * MIN_SAMPLES)
    _run(times, "DRAW", 100, {HOST: 2.0, DEVICE: 1.0}, 2 * MIN_SAMPLES)  # another class of the same kind
    assert times.choose("DRAW", 500) == HOST
    assert times.choose("SMOOTH", 500) == DEVICE
    assert times.choose("DRAW", 100) == DEVICE


def test_a_change_of_speed_is_followed():
    """The host gets slower than the device (a busy machine): once the host's fast times have left its window,
    the device takes over, and the host is only rechecked."""
    times = DabTimes(prior_host_texels=1000)
    _run(times, "DRAW", 500, {HOST: 1.0, DEVICE: 2.0}, 2 * MIN_SAMPLES + 4 * RECHECK)
    later = _run(times, "DRAW", 500, {HOST: 3.0, DEVICE: 2.0}, 2 * WINDOW + 4 * RECHECK)
    assert later[:WINDOW].count(HOST) >= WINDOW - 1  # a device recheck may fall in there
    tail = later[2 * WINDOW:]
    assert tail.count(DEVICE) >= len(tail) - 6  # from then on the device, with the host's rechecks


def test_the_shortest_recent_time_stands_for_a_side():
    """One slow spell (a build, the machine busy) does not turn the choice."""
    times = DabTimes(prior_host_texels=1000)
    for seconds in (1.0, 9.0):
        times.record("DRAW", 500, HOST, seconds)
    for seconds in (2.0, 2.0):
        times.record("DRAW", 500, DEVICE, seconds)
    assert times.choose("DRAW", 500) == HOST


def test_a_measured_class_implies_the_side_of_classes_beyond_it():
    """The device faster at 500 texels: larger footprints go to the device without trials; the host faster at
    50,000 texels (another kind): smaller footprints stay on the host without trials. Sizes in between are tried."""
    times = DabTimes(prior_host_texels=10**9)  # the prior alone would keep everything on the host
    _run(times, "DRAW", 500, {HOST: 2.0, DEVICE: 1.0}, 2 * MIN_SAMPLES + 1)
    assert _run(times, "DRAW", 5000, {HOST: 2.0, DEVICE: 1.0}, 3) == [DEVICE] * 3
    times = DabTimes(prior_host_texels=0)  # the prior alone would send everything to the device
    _run(times, "SMOOTH", 50000, {HOST: 1.0, DEVICE: 2.0}, 2 * MIN_SAMPLES + 1)
    assert _run(times, "SMOOTH", 500, {HOST: 1.0, DEVICE: 2.0}, 3) == [HOST] * 3
    assert _run(times, "DRAW", 500, {HOST: 1.0, DEVICE: 2.0}, 2) == [DEVICE, HOST]  # nothing known of DRAW: trials


def test_a_near_tie_keeps_the_verdict():
    """The device turns out a little faster than the host (within SWITCH_MARGIN): the host keeps the class and its
    rechecks stay spaced out; clearly faster, and the device takes over."""
    times = DabTimes(prior_host_texels=1000)
    _run(times, "DRAW", 500, {HOST: 1.0, DEVICE: 2.0}, 2 * MIN_SAMPLES + 1)
    assert SWITCH_MARGIN > 0.02
    close = {HOST: 1.0, DEVICE: 0.98}
    for seconds in (close[DEVICE],) * WINDOW:
        times.record("DRAW", 500, DEVICE, seconds)
    assert _run(times, "DRAW", 500, close, 3 * FIRST_RECHECK).count(HOST) >= 3 * FIRST_RECHECK - 2
    times.record("DRAW", 500, DEVICE, 0.9)
    assert times.choose("DRAW", 500) == DEVICE

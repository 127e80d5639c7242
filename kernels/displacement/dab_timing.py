"""Which side runs a dab, or a stroke, of a map, the host (numpy) or the OpenCL device: the one measured faster.

The two sides give the same bytes (``tests/displacement/test_opencl_maps.py`` compares them), so the choice decides
speed alone. Where each side wins depends on the device (a launch and a read-back cost a fixed time), on
this CPU (numpy's cost per texel), on the dab's kind (a SMOOTH texel costs numpy three to four DRAW texels) and on
the footprint's size. A single dab is timed alone (`map_edit.apply_dab`); a stroke on a device-resident map is timed
as a whole, per dab (`map_strokes.run_stroke`, `MapBuffer.stroke_times`), because its device dabs are read back
together and its DRAW dabs run as one launch: there the device usually wins (``bench/displacement.py``,
``stroke``), and strokes try it first.

`DabTimes` keeps, per (kind, footprint class), the last few times of each side; a class holds the footprints of
[2^(k-1), 2^k) texels. A new class takes the side a measured class of the kind implies (the device faster at a
smaller class, or the host at a larger one), so only sizes between the measured ones cost trials; otherwise it
starts on the side the prior picks (`PRIOR_HOST_TEXELS`) and tries the other. Once each side has `MIN_SAMPLES` times
the class runs the side whose shortest recent time is lower. The slower side is timed again after the faster has run
for `FIRST_RECHECK` of the slower side's dab times, then for twice as long after each recheck up to `RECHECK`, so a
verdict from a slow spell is soon revised and a change (a busy machine, a bigger map) is followed at about 1 /
`RECHECK` of the stroke's time; a verdict changes only for a side `SWITCH_MARGIN` faster. The shortest time, not the
mean, stands for a side: a shared machine's noise only ever adds time.
"""

import math
import weakref
from collections import deque
from dataclasses import dataclass, field

HOST, DEVICE = "host", "device"
#: Before a class has times: footprints of fewer texels than this start on the host (radius ~90; PoCL's tie).
PRIOR_HOST_TEXELS = 181 * 181
#: Times of each side needed before the faster is trusted (the first device time of a kernel includes its build).
MIN_SAMPLES = 2
#: Recent times kept per side and class.
WINDOW = 4
#: The slower side runs again once the faster has run for as long as FIRST_RECHECK of the slower side's dabs take,
#: then twice as long at each recheck, up to RECHECK: a verdict from a slow spell (a kernel built for a new
#: footprint size) is revised within a few dabs, and a steady one costs about 1 / RECHECK of a stroke's time,
#: however much slower the other side is.
FIRST_RECHECK = 4
RECHECK = 64
#: A verdict changes only for a side this much faster: near ties (both sides within 5 %) do not flip back and forth.
SWITCH_MARGIN = 0.05


def size_class(texels):
    """The footprint class of a dab of ``texels`` texels: k for [2^(k-1), 2^k)."""
    return max(int(texels), 1).bit_length()


@dataclass
class _ClassTimes:
    """Recent seconds per dab of each side in one (kind, size class), and the dabs since the slower side ran."""

    seconds: dict = field(default_factory=lambda: {HOST: deque(maxlen=WINDOW), DEVICE: deque(maxlen=WINDOW)})
    best: dict = field(default_factory=lambda: {HOST: math.inf, DEVICE: math.inf})  # inf below MIN_SAMPLES
    since_recheck: int = 0
    recheck_span: float = 0.0  # the next recheck comes after this many of the slower side's dab times
    faster: str | None = None  # the side measured faster, once both have MIN_SAMPLES times


@dataclass
class DabTimes:
    """Measured dab times of one device-resident map and the choice they give (see the module docstring)."""

    prior_host_texels: int = PRIOR_HOST_TEXELS
    classes: dict = field(default_factory=dict)  # (kind, size class) -> _ClassTimes

    def _times(self, kind, texels):
        key = (kind, size_class(texels))
        times = self.classes.get(key)
        if times is None:
            times = self.classes[key] = _ClassTimes()
        return times

    def _implied(self, kind, texels):
        """The side a measured class of ``kind`` implies for ``texels``, or None: the device's fixed cost per dab
        is spread over more texels as footprints grow, so the device faster at a smaller class is faster here too,
        and the host faster at a larger class is faster here too."""
        k = size_class(texels)
        for (other_kind, c), times in self.classes.items():
            if other_kind == kind and (times.faster == DEVICE and c < k or times.faster == HOST and c > k):
                return times.faster
        return None

    def choose(self, kind, texels):
        """`HOST` or `DEVICE` for the next dab of ``kind`` over a footprint of ``texels`` texels (the host on a tie)."""
        times = self._times(kind, texels)
        best = times.best
        if math.inf in best.values():  # a side has fewer than MIN_SAMPLES times
            prior = HOST if texels < self.prior_host_texels else DEVICE
            other = DEVICE if prior == HOST else HOST
            prior_next = len(times.seconds[prior]) <= len(times.seconds[other])  # trials alternate, prior first
            return self._implied(kind, texels) or (prior if prior_next else other)
        fast = HOST if best[HOST] <= best[DEVICE] else DEVICE
        if times.faster not in (None, fast) and best[fast] > (1 - SWITCH_MARGIN) * best[times.faster]:
            fast = times.faster  # a near tie keeps the verdict (and its rechecks spaced out)
        slow = DEVICE if fast == HOST else HOST
        t_fast, t_slow = best[fast], best[slow]
        if fast != times.faster:  # a new verdict: recheck it soon, then ever more rarely
            times.faster, times.since_recheck, times.recheck_span = fast, 0, FIRST_RECHECK
        if times.since_recheck * t_fast >= times.recheck_span * t_slow:
            times.since_recheck, times.recheck_span = 0, min(2 * times.recheck_span, RECHECK)
            return slow
        times.since_recheck += 1
        return fast

    def record(self, kind, texels, side, seconds):
        """Note that a dab of ``kind`` over ``texels`` texels took ``seconds`` on ``side``."""
        times = self._times(kind, texels)
        recent = times.seconds[side]
        recent.append(float(seconds))
        if len(recent) >= MIN_SAMPLES:
            times.best[side] = min(recent)


_TILE_TIMES = {}  # id(runtime) -> (weak reference to it, DabTimes)


def tile_times(runtime):
    """The `DabTimes` of dabs on maps without a device copy (each dab uploads its tile) on ``runtime``: one per
    runtime for the process, since such maps have no `MapBuffer` to keep them."""
    ref, times = _TILE_TIMES.get(id(runtime), (None, None))
    if ref is None or ref() is not runtime:
        times = DabTimes()
        _TILE_TIMES[id(runtime)] = (weakref.ref(runtime), times)
    return times

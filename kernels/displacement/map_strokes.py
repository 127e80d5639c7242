"""Strokes on a displacement map: dab spacing along the path, pressure, X-mirror, and tile undo ([Andrade 2012]).

A stroke is a polyline of samples ``(x, y, pressure)`` in map texels (x right, y down the rows). `stroke_dabs`
places dabs every ``spacing * radius`` texels of arc length, with pressure interpolated, the same way every time
(replay is deterministic). `run_stroke` applies them with `map_edit.apply_dab`, mirrored across the map's
vertical centre line when asked, and records the tiles it touches in a `TileUndo` before changing them: an undo
step holds only those tiles (memory proportional to the stroke's area), and restores the exact bytes.
"""

import time
from dataclasses import dataclass, field, replace

import numpy as np

from ..common.errors import InvalidInputError
from ..common.tolerances import ROUND_OFF_SLACK
from .dab_timing import HOST
from .map_edit import KINDS, DabParams, apply_dab, dab_texels, flush_deferred

TILE = 64  # undo tile edge (texels)


@dataclass
class Brush:
    """What one dab does: ``kind`` is a `map_edit.KINDS` name; radius in texels; extra kernel parameters in
    ``params``, by `map_edit.DabParams` field name (falloff, vector, depth, force, cell, seed, stamp, angle,
    scale, ...)."""

    kind: str = "DRAW"
    radius: float = 16.0
    strength: float = 0.1
    spacing: float = 0.25  # of the radius
    pressure_radius: bool = False
    pressure_strength: bool = True
    mirror_x: bool = False
    params: dict = field(default_factory=dict)

    def validate(self):
        if self.kind not in KINDS:
            raise InvalidInputError(f"Unknown brush {self.kind!r}; expected one of {', '.join(KINDS)}")
        if not (np.isfinite(self.radius) and self.radius > 0):
            raise InvalidInputError(f"The brush radius must be positive; got {self.radius!r}")
        if not (np.isfinite(self.spacing) and self.spacing > 0):
            raise InvalidInputError(f"The dab spacing must be positive; got {self.spacing!r}")
        DabParams.of(self.params)  # unknown parameter names are refused here, before any dab
        return self


def stroke_dabs(samples, spacing):
    """(n, 3) float64 dabs ``(x, y, pressure)`` every ``spacing`` texels along the (m, 3) ``samples``.

    The first dab sits on the first sample; a stroke of one sample is one dab. Pressure is linear along each
    segment. Raises `InvalidInputError` for NaN or pressures outside [0, 1].
    """
    s = np.asarray(samples, np.float64).reshape(-1, 3)
    if len(s) == 0:
        return s
    if not np.isfinite(s).all():
        raise InvalidInputError("Stroke samples must be finite")
    if s[:, 2].min() < 0 or s[:, 2].max() > 1:
        raise InvalidInputError("Stroke pressure must lie in [0, 1]")
    seg = np.hypot(*np.diff(s[:, :2], axis=0).T)
    arc = np.concatenate([[0.0], np.cumsum(seg)])
    at = np.arange(0.0, arc[-1] + ROUND_OFF_SLACK, spacing)
    return np.stack([np.interp(at, arc, s[:, i]) for i in range(3)], axis=1)


class TileUndo:
    """Before/after copies of the TILE x TILE tiles a stroke touched; `undo`/`redo` restore them exactly."""

    def __init__(self, dmap):
        self.shape = dmap.shape
        self.before = {}
        self.after = {}

    def record(self, dmap, region):
        """Save the tiles under ``region`` (x0, y0, x1, y1) that this step has not saved yet."""
        x0, y0, x1, y1 = region
        for ty in range(y0 // TILE, (y1 - 1) // TILE + 1):
            for tx in range(x0 // TILE, (x1 - 1) // TILE + 1):
                if (ty, tx) not in self.before:
                    self.before[ty, tx] = dmap[self._slices(ty, tx)].copy()

    def close(self, dmap):
        """Save the after-state of every recorded tile (for redo)."""
        self.after = {key: dmap[self._slices(*key)].copy() for key in self.before}
        return self

    def _slices(self, ty, tx):
        return slice(ty * TILE, min((ty + 1) * TILE, self.shape[0])), slice(tx * TILE, min((tx + 1) * TILE,
                                                                                             self.shape[1]))

    def _put(self, dmap, tiles):
        for key, data in tiles.items():
            dmap[self._slices(*key)] = data
        return self.region()

    def undo(self, dmap):
        return self._put(dmap, self.before)

    def redo(self, dmap):
        return self._put(dmap, self.after)

    @property
    def nbytes(self):
        return sum(a.nbytes for a in self.before.values()) + sum(a.nbytes for a in self.after.values())

    def region(self):
        """Bounding box ``(x0, y0, x1, y1)`` of the recorded tiles, or None."""
        if not self.before:
            return None
        ty, tx = np.array(list(self.before)).T
        return (int(tx.min()) * TILE, int(ty.min()) * TILE, min(int(tx.max() + 1) * TILE, self.shape[1]),
                min(int(ty.max() + 1) * TILE, self.shape[0]))


def _mirrored(dab, width):
    """The `DabParams` mirrored across x = (width - 1) / 2: positions flip, vector x components negate (only the
    parameters that were given)."""
    changes = {}
    if dab.pos is not None:
        changes["pos"] = (width - 1 - dab.pos[0], dab.pos[1])
    for key in ("vector", "force", "arg2"):
        if getattr(dab, key) is not None:
            v = np.array(getattr(dab, key), np.float64)
            v[0] = -v[0]
            changes[key] = v
    if dab.arg1 is not None:
        a = np.array(dab.arg1, np.float64)
        a[0] = width - 1 - a[0]
        changes["arg1"] = a
    if dab.angle is not None:
        changes["angle"] = np.pi - dab.angle
    return replace(dab, **changes)


def dab_params(brush, x, y, pressure):
    """The `DabParams` of one dab of ``brush`` at (x, y) with ``pressure``."""
    radius = brush.radius * (pressure if brush.pressure_radius else 1.0)
    strength = brush.strength * (pressure if brush.pressure_strength else 1.0)
    p = dict(brush.params)
    if brush.kind == "CONTACT":
        p.update(pos=(x, y), radius=radius, depth=p.get("depth", strength))
    elif brush.kind == "FORCE":
        # a cone of depth ``strength`` and the brush radius: R = |f.xyz| * f.w = radius (0 strength: refused)
        f = np.array(p.get("force", (0.0, 0.0, -strength, radius / abs(strength) if strength else 0.0)), np.float64)
        p.update(pos=(x, y), force=f)
    elif brush.kind == "TEST":
        p.update(arg1=(x, y, 0, 0), arg2=p.get("arg2", (0, 0, strength, 0)), arg3=(radius, 0, 0, 0))
    elif brush.kind == "STAMP":
        p.update(pos=(x, y), strength=strength, scale=p.get("scale", 1.0) * (radius / brush.radius))
    else:
        p.update(pos=(x, y), radius=radius, strength=strength)
    return DabParams.of(p)


def run_stroke(dmap, brush, samples, backend="auto", device=None, undo=None, progress=None, spaced=True):
    """Apply ``brush`` along ``samples`` ((m, 3) x, y, pressure). Returns the changed region or None.

    With ``spaced=False`` the samples are the dabs themselves (a live stroke that spaced them already).
    ``undo`` (a `TileUndo` of ``dmap``) records every touched tile before it changes. A dab that fails validation
    raises before it writes; earlier dabs of the stroke stay applied (undo restores them).

    On a device map (``device``) the dabs run on the device are read back together when the stroke ends
    (`map_edit.apply_dab`'s ``defer``; small DRAW, CONTACT, FORCE and NOISE dabs run as one launch,
    `dab_batch`), with the same bytes as dab by dab. There
    ``auto`` picks one side for the whole stroke: the one whose strokes took less time per dab for this kind and
    footprint size (`MapBuffer.stroke_times`, a `dab_timing.DabTimes` timing strokes; it tries the device first).
    A map without a device copy picks per dab (`map_edit.apply_dab`).
    """
    brush.validate()
    dabs = stroke_dabs(samples, brush.spacing * brush.radius) if spaced else np.asarray(samples, np.float64)
    width = dmap.shape[1]
    box = None
    times = device.stroke_times if device is not None and backend == "auto" and len(dabs) else None
    if times is not None:
        texels = dab_texels(dmap, brush.kind, dab_params(brush, *dabs[0]))
        side = times.choose(brush.kind, texels)
        backend = "numpy" if side == HOST else "opencl"
        start = time.perf_counter()
    try:
        for i, (x, y, pressure) in enumerate(dabs):
            dab = dab_params(brush, x, y, pressure)
            todo = [dab, _mirrored(dab, width)] if brush.mirror_x else [dab]
            for d in todo:
                box = union_region(box, _apply(dmap, brush.kind, d, backend, device, undo))
            if progress is not None and i % 64 == 0:
                progress((i + 1) / len(dabs))
    finally:  # the dabs applied so far reach the host, whether the stroke ends or a dab is refused
        if device is not None:
            flush_deferred(device)
    if times is not None:
        times.record(brush.kind, texels, side, (time.perf_counter() - start) / (len(dabs) * (1 + brush.mirror_x)))
    return box


def _apply(dmap, kind, dab, backend, device, undo):
    before = None if undo is None else (lambda region: undo.record(dmap, region))
    return apply_dab(dmap, kind, backend=backend, device=device, before_write=before, dab=dab, defer=True)


def union_region(a, b):
    """Bounding box of two regions ``(x0, y0, x1, y1)``; either may be None."""
    if a is None or b is None:
        return a or b
    return min(a[0], b[0]), min(a[1], b[1]), max(a[2], b[2]), max(a[3], b[3])

"""Applying dabs to a displacement map: validation, footprints, and the OpenCL or numpy kernel.

`apply_dab(map, kind, backend=..., **params)` edits ``map`` (H, W, C) float32 in place, touching only the
dab's footprint (a tile: the bounding box of the disc, clipped to the map), and returns that tile's
``(x0, y0, x1, y1)``. Bad parameters (NaN, a force whose radius |f.xyz|·f.w is not positive, a stamp with the
wrong channel count) and NaN inside the footprint raise `InvalidInputError` before anything is written, so
the map is unchanged. OpenCL (``map_dabs.cl``) and numpy (`map_dabs`) give the same result.

`compile_custom` builds a user kernel body into [Andrade 2012]'s custom template; compiler errors come back as
`TesseraError` with the compiler log.
"""

import math
import time
from dataclasses import dataclass, fields

import numpy as np

from ..common.budget import check_bytes
from ..common.errors import InvalidInputError, TesseraError
from ..common.opencl_runtime import backend_runtime
from ..common.typed_kernel import TypedKernel
from . import dab_batch
from . import map_dabs as ref
from .dab_timing import HOST, tile_times
from .map_buffer import DeferredDab, MapBuffer

KINDS = ("CONTACT", "FORCE", "TEST", "DRAW", "SMOOTH", "FLATTEN", "STAMP", "NOISE")
_FALLOFF_ID = {name: i for i, name in enumerate(ref.FALLOFFS)}
#: Memory per texel of a map being edited: Blender's float RGBA image (16 B), the RGBA mirror written to it
#: (16 B), the pixels read at creation (16 B), plus per channel the host map and its device copy (8 B).
MAP_BYTES_PER_TEXEL = 48
MAP_BYTES_PER_CHANNEL = 8


def check_map_budget(width, height, channels, budget_bytes):
    """Raise `BudgetError` when a ``width`` x ``height`` map with ``channels`` would need more than
    ``budget_bytes`` (0 or None: no limit) while edited."""
    need = int(width) * int(height) * (MAP_BYTES_PER_TEXEL + MAP_BYTES_PER_CHANNEL * int(channels))
    return check_bytes(need, budget_bytes, f"A {width} x {height} map would be edited", "a smaller map")


def check_map(dmap):
    """A displacement map must be a writable, C-contiguous (H, W, C) float32 array with C in 1, 3, 4."""
    if not isinstance(dmap, np.ndarray) or dmap.dtype != np.float32 or dmap.ndim != 3 or dmap.shape[2] not in (1, 3, 4):
        raise InvalidInputError("A displacement map is a float32 array of shape (height, width, 1, 3 or 4)")
    if not dmap.flags.c_contiguous or not dmap.flags.writeable:
        raise InvalidInputError("The displacement map must be a writable, contiguous array")
    return dmap


def _finite(name, value):
    v = np.asarray(value, np.float64)
    if not np.isfinite(v).all():
        raise InvalidInputError(f"Dab parameter {name!r} must be finite; got {value!r}")
    return v


def footprint(shape, pos, radius):
    """Tile ``(x0, y0, x1, y1)`` (end exclusive) of the texels with distance < radius, clipped; None if empty."""
    h, w = shape[:2]
    x0 = max(0, math.floor(pos[0] - radius))
    y0 = max(0, math.floor(pos[1] - radius))
    x1 = min(w, math.ceil(pos[0] + radius) + 1)
    y1 = min(h, math.ceil(pos[1] + radius) + 1)
    if x1 <= x0 or y1 <= y0 or radius <= 0:
        return None
    return x0, y0, x1, y1


@dataclass(frozen=True)
class DabParams:
    """The parameters of one dab, as `apply_dab` takes them by keyword. None means "not given": the kind's
    default applies (below), and a mirrored stroke leaves it alone.

    pos: (x, y) texels (every kind but TEST); radius: texels (CONTACT and the brushes); strength (brushes and
    STAMP, default 1) times pressure (default 1); falloff: a `map_dabs.FALLOFFS` name (brushes, default SMOOTH);
    depth (CONTACT); force: float4, radius |f.xyz| * f.w (FORCE); vector: float4 offset direction (DRAW, NOISE,
    default (0, 0, 1, 0)); cell, seed: noise lattice size (default 8) and seed (NOISE); target: float4 height or
    vector to flatten toward (FLATTEN, default the mean under the brush); stamp: (h, w, C) array, scale (default
    1) and angle (default 0) (STAMP); arg1..arg4: [Andrade 2012]'s test kernel's four float4 (TEST, default 0).
    """

    pos: tuple | None = None
    radius: float | None = None
    strength: float | None = None
    pressure: float | None = None
    falloff: str | None = None
    depth: float | None = None
    force: tuple | None = None
    vector: tuple | None = None
    cell: float | None = None
    seed: int | None = None
    target: tuple | None = None
    stamp: np.ndarray | None = None
    scale: float | None = None
    angle: float | None = None
    arg1: tuple | None = None
    arg2: tuple | None = None
    arg3: tuple | None = None
    arg4: tuple | None = None

    @classmethod
    def of(cls, params):
        """From keyword arguments; an unknown name is refused with the list of known ones."""
        unknown = sorted(set(params) - _PARAM_NAMES)
        if unknown:
            raise InvalidInputError(f"Unknown dab parameter(s) {', '.join(unknown)}; known: "
                                    f"{', '.join(sorted(_PARAM_NAMES))}")
        return cls(**params)

    def required(self, kind, name):
        value = getattr(self, name)
        if value is None:
            raise InvalidInputError(f"A {kind} dab needs {name!r}")
        return _finite(name, value)

    def optional(self, name, default):
        value = getattr(self, name)
        return _finite(name, default if value is None else value)

    def scaled_strength(self):
        """strength x pressure (each 1 when not given); pressure outside [0, 1] is refused."""
        pressure = float(self.optional("pressure", 1.0))
        if not 0.0 <= pressure <= 1.0:
            raise InvalidInputError(f"Pressure must lie in [0, 1]; got {pressure:g}")
        return float(self.optional("strength", 1.0)) * pressure


_PARAM_NAMES = {f.name for f in fields(DabParams)}


@dataclass(frozen=True)
class DabPlan:
    """A validated dab: its footprint ``region`` (x0, y0, x1, y1) or None; ``reference`` the numpy function
    (``tile, x0, y0`` and, for SMOOTH, ``src, sx0, sy0``) that edits the tile in place; ``kernel`` the OpenCL kernel
    name in ``map_dabs.cl`` and ``args`` its scalar arguments."""

    region: tuple | None
    reference: object
    kernel: str
    args: tuple


def _plan_contact(dmap, d):
    pos, depth, radius = d.required("CONTACT", "pos"), d.required("CONTACT", "depth"), d.required("CONTACT", "radius")
    return DabPlan(footprint(dmap.shape, pos, float(radius)),
                   lambda t, x0, y0: ref.contact(t, x0, y0, pos, depth, radius), "contact",
                   (_f2(pos), np.float32(depth), np.float32(radius)))


def _plan_force(dmap, d):
    pos, f = d.required("FORCE", "pos"), d.required("FORCE", "force")
    area = ref.force_area(f)
    if not area > 0:
        raise InvalidInputError(f"The force's radius |f.xyz| * f.w must be positive; got {float(area):g} "
                                f"(f = {tuple(float(x) for x in f)})")
    return DabPlan(footprint(dmap.shape, pos, float(area)), lambda t, x0, y0: ref.force(t, x0, y0, pos, f),
                   "force", (_f2(pos), _f4(f), np.float32(area)))


def _plan_test(dmap, d):
    args = [d.optional(f"arg{i}", (0, 0, 0, 0)) for i in range(1, 5)]
    return DabPlan(footprint(dmap.shape, args[0][:2], float(args[2][0])),
                   lambda t, x0, y0: ref.test(t, x0, y0, *args), "test", tuple(_f4(a) for a in args))


def _plan_brush(dmap, d, kind):
    """DRAW, FLATTEN, SMOOTH and NOISE: a disc with a falloff."""
    pos, radius = d.required(kind, "pos"), float(d.required(kind, "radius"))
    strength = d.scaled_strength()
    falloff = "SMOOTH" if d.falloff is None else d.falloff
    if falloff not in _FALLOFF_ID:
        raise InvalidInputError(f"Falloff must be one of {ref.FALLOFFS}; got {falloff!r}")
    region = footprint(dmap.shape, pos, radius)
    base = (_f2(pos), np.float32(radius), np.float32(strength), np.int32(_FALLOFF_ID[falloff]))
    if kind == "DRAW":
        vec = d.optional("vector", (0, 0, 1, 0))
        return DabPlan(region, lambda t, x0, y0: ref.draw(t, x0, y0, pos, radius, strength, falloff, vec), "draw",
                       base + (_f4(vec),))
    if kind == "NOISE":
        vec = d.optional("vector", (0, 0, 1, 0))
        cell = float(d.optional("cell", 8.0))
        seed = int(0 if d.seed is None else d.seed) & 0xFFFFFFFF
        if not cell > 0:
            raise InvalidInputError(f"The noise cell size must be positive; got {cell:g}")
        return DabPlan(region, lambda t, x0, y0: ref.noise(t, x0, y0, pos, radius, strength, falloff, vec, cell,
                                                           seed), "noise", base + (_f4(vec), np.float32(cell),
                                                                                   np.uint32(seed)))
    if kind == "FLATTEN":
        target = d.target
        if target is None and region is not None:
            x0, y0, x1, y1 = region
            target = _flatten_target(dmap[y0:y1, x0:x1], x0, y0, pos, radius)
        target = _finite("target", target if target is not None else (0, 0, 0, 0))
        return DabPlan(region, lambda t, x0, y0: ref.flatten(t, x0, y0, pos, radius, strength, falloff, target),
                       "flatten", base + (_f4(target),))
    return DabPlan(region, lambda t, x0, y0, src, sx0, sy0: ref.smooth(t, x0, y0, src, sx0, sy0, pos, radius,
                                                                        strength, falloff), "smooth", base)


def _plan_stamp(dmap, d):
    channels = dmap.shape[2]
    st = d.stamp
    if not isinstance(st, np.ndarray) or st.ndim != 3 or st.shape[2] != channels or st.shape[0] < 1:
        raise InvalidInputError(f"The stamp must be a (height, width, {channels}) array like the map")
    st = np.ascontiguousarray(st, np.float32)
    if not np.all(np.isfinite(st)):
        raise InvalidInputError("The stamp contains NaN or infinite values")
    pos, scale = d.required("STAMP", "pos"), float(d.optional("scale", 1.0))
    if scale <= 0:
        raise InvalidInputError("The stamp scale must be positive")
    strength = d.scaled_strength()
    rot = ref.stamp_rotation(float(d.optional("angle", 0.0)))
    return DabPlan(footprint(dmap.shape, pos, ref.stamp_extent(st.shape, scale) + 1.0),
                   lambda t, x0, y0: ref.stamp(t, x0, y0, st, pos, rot, scale, strength), "stamp",
                   (st, _f2(pos), rot, np.float32(scale), np.float32(strength)))


_PLANNERS = {
    "CONTACT": _plan_contact, "FORCE": _plan_force, "TEST": _plan_test, "STAMP": _plan_stamp,
    "DRAW": lambda m, d: _plan_brush(m, d, "DRAW"), "SMOOTH": lambda m, d: _plan_brush(m, d, "SMOOTH"),
    "FLATTEN": lambda m, d: _plan_brush(m, d, "FLATTEN"), "NOISE": lambda m, d: _plan_brush(m, d, "NOISE"),
}


def plan_dab(dmap, kind, dab):
    """Validate one dab (a `DabParams`) of ``kind`` on ``dmap``: a `DabPlan`, or `InvalidInputError`."""
    planner = _PLANNERS.get(kind)
    if planner is None:
        raise InvalidInputError(f"Unknown dab kind {kind!r}; expected one of {', '.join(KINDS)}")
    return planner(dmap, dab)


def dab_texels(dmap, kind, dab):
    """The number of texels in the footprint of ``dab`` (a `DabParams` of ``kind``) on ``dmap``; 0 off the map."""
    region = plan_dab(dmap, kind, dab).region
    return 0 if region is None else _area(region)


def _flatten_target(tile, x0, y0, pos, radius):
    """The falloff-free mean of the texels inside the disc, as a float4 (xyz(w) or z for height maps)."""
    h, w, c = tile.shape
    inside = ref.texel_distance(x0, y0, w, h, pos) < np.float32(radius)
    mean = tile[inside].astype(np.float64).mean(axis=0) if inside.any() else np.zeros(c)
    out = np.zeros(4)
    if c == 1:
        out[2] = mean[0]
    else:
        out[:c] = mean
    return out


# OpenCL float2 / float4 kernel arguments passed by value
_FLOAT2 = np.dtype([("x", np.float32), ("y", np.float32)])
_FLOAT4 = np.dtype([("x", np.float32), ("y", np.float32), ("z", np.float32), ("w", np.float32)])


def _f2(v):
    return np.array(np.asarray(v, np.float64)[:2], np.float32).view(_FLOAT2)[0]


def _f4(v):
    return np.array(np.asarray(v, np.float64).reshape(4), np.float32).view(_FLOAT4)[0]


def _runtime(backend):
    return backend_runtime(backend, "the map edit")


def _backend_runtime(backend, device):
    """The OpenCL runtime to use, or None for numpy; a device-resident map always runs on its device, with the
    runtime (context, queue, programs) its buffer was made in, whatever the current runtime is."""
    return device.runtime if device is not None else _runtime(backend)


def apply_dab(dmap, kind, backend="auto", device=None, before_write=None, dab=None, defer=False, **params):
    """Apply one dab in place. Returns the footprint ``(x0, y0, x1, y1)`` or None when it misses the map.

    The dab's parameters are a `DabParams` (``dab``) or its fields as keywords.

    ``device`` (a `MapBuffer` over ``dmap``) keeps the map on the OpenCL device between dabs, so only the
    footprint moves; without it the footprint tile is uploaded and read back. ``backend`` picks per dab:
    ``"opencl"`` always runs on the device; ``"numpy"`` always on the host; ``"auto"`` on the side measured faster
    for the dab's kind and footprint (`dab_timing.DabTimes`, kept by the buffer, or per runtime for maps without
    one: small footprints usually on the host, where a launch and read-back cost more than the arithmetic). A
    host dab marks its footprint for the device, which gets it before its next operation (`MapBuffer.mark_stale`).
    ``before_write(region)`` is called once every check has passed and before anything is written (undo records
    the region there).

    ``defer=True`` with ``backend="opencl"`` and ``device`` leaves the dab on the device (`MapBuffer.defer`; a
    small DRAW, CONTACT, FORCE or NOISE dab is not even launched yet: `launch_batched` runs such dabs together,
    `dab_batch`): the caller reads the dabs back with `flush_deferred` (`map_strokes.run_stroke` does, at the end
    of a stroke, and times the stroke as a whole). A host dab, an undeferred dab and a FLATTEN dab (it reads the
    map under it) flush earlier deferred dabs first.
    """
    check_map(dmap)
    if device is not None and device.host is not dmap:
        raise InvalidInputError("The device buffer mirrors a different map")
    if dab is not None and params:
        raise InvalidInputError("Give the dab's parameters as a DabParams or as keywords, not both")
    dab = dab if dab is not None else DabParams.of(params)
    defer = defer and backend == "opencl" and device is not None
    if device is not None and (not defer or kind == "FLATTEN"):
        flush_deferred(device)
    plan = plan_dab(dmap, kind, dab)
    region, numpy_fn, cl_name, cl_args = plan.region, plan.reference, plan.kernel, plan.args
    if region is None:
        return None
    x0, y0, x1, y1 = region
    halo = None
    if kind == "SMOOTH":
        halo = (max(0, x0 - 1), max(0, y0 - 1), min(dmap.shape[1], x1 + 1), min(dmap.shape[0], y1 + 1))
    _check_finite(dmap, halo or region)
    times, area = _dab_times(backend, device), _area(region)
    side = times.choose(kind, area) if times is not None else None
    on_host = backend == "numpy" or side == HOST
    if on_host and device is not None:
        flush_deferred(device)
    runtime = None if on_host else _backend_runtime(backend, device)
    deferred = defer and runtime is not None
    batch_row = None
    if before_write is not None:
        before_write(region)
    start = time.perf_counter()
    if runtime is None:
        tile = dmap[y0:y1, x0:x1].copy()  # scratch: committed only when every value is finite
        with np.errstate(over="ignore", invalid="ignore"):  # an overflow is refused by _commit, not warned about
            if kind == "SMOOTH":
                hx0, hy0, hx1, hy1 = halo
                numpy_fn(tile, x0, y0, dmap[hy0:hy1, hx0:hx1].copy(), hx0, hy0)
            else:
                numpy_fn(tile, x0, y0)
        _commit(dmap, region, tile)
        if device is not None:
            device.mark_stale(region)
    elif deferred and cl_name in dab_batch.BATCHED and area <= dab_batch.MAX_TEXELS:  # launched with the others
        device.sync()  # host edits go over now: while dabs are deferred, the host has nothing the device lacks
        batch_row = dab_batch.row(cl_name, cl_args)
    else:
        if device is not None:
            launch_batched(device)
        _run_opencl(runtime, dmap, region, cl_name, cl_args, halo, device, pull=not deferred)
    if deferred:
        device.defer(region, DeferredDab(kind, dab, region, cl_name, batch_row))
    if times is not None:
        times.record(kind, area, side, time.perf_counter() - start)
    return region


def flush_deferred(device):
    """Read back the dabs `apply_dab` deferred on ``device`` (a `MapBuffer`): their bounding box when every value
    there is finite. Otherwise the device is put back as the host has it and the dabs run again one at a time,
    each read back, so the first that writes NaN or infinities raises `InvalidInputError` with the ones before it
    applied, as without deferral. If the device fails meanwhile, it is put back as the host has it (the host holds
    every dab up to the stroke) and the error goes on."""
    batch = device.take_deferred()
    if batch is None:
        return
    try:
        _launch_waiting(device, batch.dabs)
        if device.pull_finite(batch.region):
            return
    except BaseException:
        device.push(batch.region)
        raise
    for d in batch.dabs:
        apply_dab(device.host, d.kind, backend="opencl", device=device, dab=d.params)


def launch_batched(device):
    """Queue the deferred dabs of ``device`` that wait for a batched launch (`dab_batch`); they stay deferred (not
    read back)."""
    if device.deferred is not None:
        _launch_waiting(device, device.deferred.dabs)


def _launch_waiting(device, dabs):
    """One batched launch for the waiting dabs (`DeferredDab` with a row), in order."""
    waiting = [d for d in dabs if d.row is not None]
    if waiting:
        dab_batch.launch(device, [d.row for d in waiting], [d.region for d in waiting])
        for d in waiting:
            d.row = None


def _dab_times(backend, device):
    """The `dab_timing.DabTimes` that picks the side of an ``auto`` dab: the device map's, or the runtime's for maps
    without a device copy; None when nothing is to be picked (another backend, or no OpenCL)."""
    if backend != "auto":
        return None
    if device is not None:
        return device.dab_times
    runtime = _runtime(backend)
    return tile_times(runtime) if runtime is not None else None


def _area(region):
    x0, y0, x1, y1 = region
    return (x1 - x0) * (y1 - y0)


def smooth_map(dmap, strength=1.0, backend="auto", device=None):
    """Smooth the whole map toward its 3x3 means (clamped borders) in place; returns the region (all of it).

    With OpenCL the map goes through the device once (`MapBuffer.smooth_all`, ping-pong buffers); a temporary
    device copy is made when no ``device`` is given.
    """
    check_map(dmap)
    k = float(_finite("strength", strength))
    h, w = dmap.shape[:2]
    if device is not None and device.host is not dmap:
        raise InvalidInputError("The device buffer mirrors a different map")
    runtime = _backend_runtime(backend, device)
    if runtime is None:
        _check_finite(dmap, (0, 0, w, h))
        _commit(dmap, (0, 0, w, h), ref.smooth_full(dmap, k))
    elif not (device or MapBuffer(runtime, dmap)).smooth_all(k):
        raise InvalidInputError("The map has NaN or infinite values; nothing was changed")
    return 0, 0, w, h


_NOT_FINITE = "The edit would write NaN or infinite values (are its strength or parameters huge?); nothing was changed"


def _commit(dmap, region, tile):
    """Write the scratch ``tile`` into ``region`` of the map, or refuse (map unchanged) if it is not all finite."""
    if not np.isfinite(tile).all():
        raise InvalidInputError(_NOT_FINITE)
    x0, y0, x1, y1 = region
    dmap[y0:y1, x0:x1] = tile


def _check_finite(dmap, region):
    x0, y0, x1, y1 = region
    if not np.isfinite(dmap[y0:y1, x0:x1]).all():
        raise InvalidInputError("The map has NaN or infinite values under the brush; nothing was changed")


def _run_opencl(runtime, dmap, region, name, args, halo, device, pull=True):
    """One kernel launch over the footprint, on the device-resident map (read back unless ``pull`` is False) or on
    an uploaded tile."""
    cl = runtime.cl
    mf = cl.mem_flags
    x0, y0, x1, y1 = region
    w, h, channels = x1 - x0, y1 - y0, dmap.shape[2]
    if device is not None:
        buf, base, mem_w = device.sync(), (y0 * dmap.shape[1] + x0) * channels, dmap.shape[1]
    else:
        tile = dmap[y0:y1, x0:x1].copy()  # scratch (a copy even when the region is the whole map)
        buf, base, mem_w = runtime.buffer(mf.READ_WRITE | mf.COPY_HOST_PTR, hostbuf=tile), 0, w
    extra = []
    if name == "smooth":
        hx0, hy0, hx1, hy1 = halo
        if device is not None:
            src = device.snapshot(halo)
        else:
            src = runtime.buffer(mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=np.ascontiguousarray(dmap[hy0:hy1, hx0:hx1]))
        extra = [src, np.int32(hx1 - hx0), np.int32(hy1 - hy0), np.int32(hx0), np.int32(hy0)]
    if name == "stamp":
        st = args[0]
        st_buf = device.stamp_buffer(st) if device is not None else runtime.buffer(mf.READ_ONLY | mf.COPY_HOST_PTR,
                                                                              hostbuf=st)
        extra = [st_buf, np.int32(st.shape[1]), np.int32(st.shape[0])]
        args = args[1:]
    kernel = runtime.kernel(ref.MAP_PROGRAM, name)
    kernel(runtime.queue, (w, h), None, buf, np.int64(base), np.int32(mem_w), np.int32(channels), np.int32(x0),
           np.int32(y0), np.int32(w), np.int32(h), *extra, *args)
    if device is not None:
        if pull and not device.pull_finite(region):
            raise InvalidInputError(_NOT_FINITE)
    else:
        cl.enqueue_copy(runtime.queue, tile, buf)
        _commit(dmap, region, tile)


def morph(a, b, time, backend="auto"):
    """Seed morphing: a new map a * (1 - t) + b * t; ``a`` and ``b`` are not modified."""
    check_map(a)
    check_map(b)
    if a.shape != b.shape:
        raise InvalidInputError(f"Morphing needs two maps of the same shape; got {a.shape} and {b.shape}")
    t = float(_finite("time", time))
    runtime = _runtime(backend)
    if runtime is None:
        return ref.morphing(a, b, t)
    cl = runtime.cl
    mf = cl.mem_flags
    out = np.empty_like(a)
    d_a = runtime.buffer(mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=a)
    d_b = runtime.buffer(mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=b)
    d_out = runtime.buffer(mf.WRITE_ONLY, out.nbytes)
    runtime.kernel(ref.MAP_PROGRAM, "morphing")(runtime.queue, (a.size,), None, d_a, d_b, d_out, np.int64(a.size),
                                          np.float32(t))
    cl.enqueue_copy(runtime.queue, out, d_out)
    return out


CUSTOM_TEMPLATE = """
#pragma OPENCL FP_CONTRACT OFF
__kernel void custom(__global float *map, const long base, const int mem_w, const int channels, const int x0,
                     const int y0, const int w, const int h, const float4 arg1, const float4 arg2, const float4 arg3,
                     const float4 arg4)
{
  const int gx = get_global_id(0), gy = get_global_id(1);
  if (gx >= w || gy >= h) {
    return;
  }
  const int x = x0 + gx, y = y0 + gy;
  __global float *t = map + base + ((long)gy * mem_w + gx) * channels;
  float4 image = (float4)(0.0f);
  if (channels == 1) { image.z = t[0]; } else { for (int c = 0; c < channels; ++c) { ((float *)&image)[c] = t[c]; } }
  (void)x; (void)y; (void)arg1; (void)arg2; (void)arg3; (void)arg4;
#line 1 "custom body"
%s
  if (channels == 1) { t[0] = image.z; } else { for (int c = 0; c < channels; ++c) { t[c] = ((float *)&image)[c]; } }
}
"""


def compile_custom(runtime, body):
    """Build a custom kernel: ``body`` edits ``float4 image`` at texel (x, y) with arg1..arg4 ([Andrade 2012] §5.7).

    Raises `TesseraError` with the compiler log on a compile error. Returns the kernel.
    """
    cl = runtime.cl
    try:
        program = cl.Program(runtime.context, CUSTOM_TEMPLATE % body).build(options=list(runtime.base_options))
    except cl.RuntimeError as err:
        raise TesseraError(f"The custom kernel failed to compile:\n{err}") from err
    return TypedKernel(cl, program, "custom")


def apply_custom(dmap, kernel, runtime, region=None, args=((0, 0, 0, 0),) * 4, device=None):
    """Run a compiled custom kernel over ``region`` (default: the whole map) in place; returns the region.

    The kernel runs on a copy of the region, so output with NaN or infinities is refused with the map unchanged;
    a `MapBuffer` given as ``device`` is updated afterwards.
    """
    check_map(dmap)
    h, w = dmap.shape[:2]
    x0, y0, x1, y1 = region or (0, 0, w, h)
    vals = [_f4(_finite(f"arg{i + 1}", a)) for i, a in enumerate(args)]
    tile = dmap[y0:y1, x0:x1].copy()  # scratch: never a view of the map, even when the region is all of it
    cl = runtime.cl
    d_tile = runtime.buffer(cl.mem_flags.READ_WRITE | cl.mem_flags.COPY_HOST_PTR, hostbuf=tile)
    kernel(runtime.queue, (x1 - x0, y1 - y0), None, d_tile, np.int64(0), np.int32(x1 - x0), np.int32(dmap.shape[2]),
           np.int32(x0), np.int32(y0), np.int32(x1 - x0), np.int32(y1 - y0), *vals)
    cl.enqueue_copy(runtime.queue, tile, d_tile)
    if not np.all(np.isfinite(tile)):
        raise TesseraError("The custom kernel produced NaN or infinite values; the map was left unchanged")
    dmap[y0:y1, x0:x1] = tile
    if device is not None:
        device.push((x0, y0, x1, y1))
    return x0, y0, x1, y1

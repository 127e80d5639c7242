"""Displacement-map edits in numpy: the reference for every kernel of ``map_dabs.cl`` ([Andrade 2012, ch. 5] and its
test values).

A map is (H, W, C) float32 with C = 1 (height) or 3 (vector, xyz) or 4 ([Andrade 2012]'s float4 texels); texel
(x, y) is ``map[y, x]`` and distances run to integer texel coordinates ([Andrade 2012, correction 1]). A float4
operand (force, the test kernel's "normal", a brush direction) maps onto the channels as xyzw / xyz / z. Each function
edits only ``tile`` = the footprint rows ``y0:y0+h`` and columns ``x0:x0+w`` (a view or copy of the map there),
in the same float32 operations as the OpenCL kernel, so the two agree to the last bit in practice.

Faithful kernels: `contact` (hard disc, z -= depth), `force` (linear cone of radius |f.xyz|·f.w on all
channels), `test` (hard disc, += arg2), `morphing` (lerp of two whole maps). Artist brushes: `draw`
(raise/lower along a vector with a falloff curve), `smooth` (toward the 3x3 mean), `flatten` (toward a
target), `stamp` (another map as a decal, rotated and scaled).
"""

import numpy as np

#: The OpenCL program these functions are the reference of (``map_dabs.cl`` beside this file).
MAP_PROGRAM = "displacement/map_dabs"
FALLOFFS = ("SMOOTH", "SPHERE", "LINEAR", "SHARP", "CONSTANT")
F32 = np.float32


def operand(vec4, channels):
    """The float4 ``vec4`` as a (C,) float32 operand: xyzw, xyz, or z for a height map."""
    v = np.asarray(vec4, F32).reshape(4)
    return v[2:3] if channels == 1 else v[:channels]


def height_channel(channels):
    return 0 if channels == 1 else 2


def texel_distance(x0, y0, w, h, pos):
    """(h, w) float32 distances from ``pos`` to the integer texel coordinates of a tile."""
    px, py = F32(pos[0]), F32(pos[1])
    dx = np.arange(x0, x0 + w, dtype=F32) - px
    dy = np.arange(y0, y0 + h, dtype=F32) - py
    return np.sqrt(dy[:, None] * dy[:, None] + dx[None, :] * dx[None, :])


def falloff(t, kind):
    """Falloff (float32) for t = d / r in [0, 1): SMOOTH 3s²-2s³ with s = 1-t, SPHERE, LINEAR, SHARP, CONSTANT."""
    t = np.asarray(t, F32)
    s = F32(1) - t
    if kind == "SMOOTH":
        return s * s * (F32(3) - F32(2) * s)
    if kind == "SPHERE":
        return np.sqrt(F32(1) - t * t)
    if kind == "LINEAR":
        return s
    if kind == "SHARP":
        return s * s
    return np.ones_like(t)


def contact(tile, x0, y0, pos, depth, radius):
    """Seed contact kernel: texels with d < radius lose ``depth`` in the height channel (z)."""
    h, w, c = tile.shape
    inside = texel_distance(x0, y0, w, h, pos) < F32(radius)
    tile[..., height_channel(c)][inside] -= F32(depth)


def force_area(f):
    """R = |f.xyz| * f.w in float32 ([Andrade 2012]'s CONSTANT travels in f.w)."""
    f = np.asarray(f, F32)
    return np.sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]) * f[3]


def force(tile, x0, y0, pos, f):
    """Seed force kernel: where 1 - d/R > 0, every channel += f * (1 - d/R) (w gets f.w too)."""
    h, w, c = tile.shape
    area = force_area(f)
    dissipation = (area - texel_distance(x0, y0, w, h, pos)) / area  # 1 - d/R, exact at [Andrade 2012]'s test values
    inside = dissipation > 0
    tile[inside] += operand(f, c)[None, :] * dissipation[inside][:, None]


def test(tile, x0, y0, arg1, arg2, arg3, arg4=None):
    """Seed test kernel (the custom template edited): d(arg1.xy) < arg3.x -> += arg2."""
    h, w, c = tile.shape
    inside = texel_distance(x0, y0, w, h, np.asarray(arg1, F32)[:2]) < F32(np.asarray(arg3, F32)[0])
    tile[inside] += operand(arg2, c)[None, :]


def morphing(a, b, time):
    """Seed morphing kernel: a * (1 - t) + b * t over whole maps (new array; a and b are not touched)."""
    t = F32(time)
    return a * (F32(1) - t) + b * t


def _weights(x0, y0, w, h, pos, radius, strength, kind):
    d = texel_distance(x0, y0, w, h, pos)
    inside = d < F32(radius)
    k = F32(strength) * falloff(d[inside] / F32(radius), kind)
    return inside, k


def draw(tile, x0, y0, pos, radius, strength, kind, vec):
    """Raise (strength > 0) or lower along ``vec`` (float4) with a falloff curve."""
    h, w, c = tile.shape
    inside, k = _weights(x0, y0, w, h, pos, radius, strength, kind)
    tile[inside] += operand(vec, c)[None, :] * k[:, None]


def flatten(tile, x0, y0, pos, radius, strength, kind, target):
    """Move texels toward ``target`` (float4 operand) with a falloff curve."""
    h, w, c = tile.shape
    inside, k = _weights(x0, y0, w, h, pos, radius, strength, kind)
    v = tile[inside]
    tile[inside] = v + (operand(target, c)[None, :] - v) * k[:, None]


def smooth(tile, x0, y0, src, sx0, sy0, pos, radius, strength, kind):
    """Move texels toward the mean of their 3x3 neighbourhood in ``src`` (a halo tile at sx0, sy0, clamped)."""
    h, w, c = tile.shape
    hs, ws = src.shape[:2]
    inside, k = _weights(x0, y0, w, h, pos, radius, strength, kind)
    xs = np.arange(x0, x0 + w) - sx0
    ys = np.arange(y0, y0 + h) - sy0
    total = np.zeros((h, w, c), F32)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            rows = np.clip(ys + dy, 0, hs - 1)
            cols = np.clip(xs + dx, 0, ws - 1)
            total += src[rows[:, None], cols[None, :]]
    mean = total[inside] / F32(9)
    v = tile[inside]
    tile[inside] = v + (mean - v) * k[:, None]


def stamp_rotation(angle):
    return np.array([np.cos(angle), np.sin(angle)], F32)


def stamp_extent(stamp_shape, scale):
    """Radius (texels) of the disc that holds a stamp of (sh, sw) texels at ``scale``."""
    sh, sw = stamp_shape[:2]
    return 0.5 * float(np.hypot(sw - 1, sh - 1)) * float(scale)


def stamp(tile, x0, y0, st, pos, rot, scale, strength):
    """Add ``strength`` x the bilinear sample of stamp ``st`` (sh, sw, C), centred at ``pos``, rotated, scaled."""
    h, w, c = tile.shape
    sh, sw = st.shape[:2]
    px, py = F32(pos[0]), F32(pos[1])
    dx = (np.arange(x0, x0 + w, dtype=F32) - px)[None, :]
    dy = (np.arange(y0, y0 + h, dtype=F32) - py)[:, None]
    rx, ry, sc = rot[0], rot[1], F32(scale)
    u = (rx * dx + ry * dy) / sc + F32(0.5) * F32(sw - 1)
    v = (rx * dy - ry * dx) / sc + F32(0.5) * F32(sh - 1)
    inside = (u >= 0) & (v >= 0) & (u <= F32(sw - 1)) & (v <= F32(sh - 1))
    u, v = u[inside], v[inside]
    iu = np.minimum(u.astype(np.int32), max(sw - 2, 0))
    iv = np.minimum(v.astype(np.int32), max(sh - 2, 0))
    fu, fv = (u - iu.astype(F32))[:, None], (v - iv.astype(F32))[:, None]
    iu1, iv1 = np.minimum(iu + 1, sw - 1), np.minimum(iv + 1, sh - 1)
    a, b, p, q = st[iv, iu], st[iv, iu1], st[iv1, iu], st[iv1, iu1]
    top = a + (b - a) * fu
    bottom = p + (q - p) * fu
    tile[inside] += F32(strength) * (top + (bottom - top) * fv)


def _lattice(ix, iy, seed):
    """Random lattice values in [-1, 1] (float32) from integer coordinates: the same hash as ``lattice()``."""
    with np.errstate(over="ignore"):
        k = (ix.astype(np.uint32) * np.uint32(0x8DA6B343)) ^ (iy.astype(np.uint32) * np.uint32(0xD8163841)) \
            ^ (np.uint32(seed) * np.uint32(0xCB1AB31F))
        k ^= k >> np.uint32(13)
        k *= np.uint32(0x5BD1E995)
        k ^= k >> np.uint32(15)
    return (k & np.uint32(0xFFFFFF)).astype(F32) * (F32(2) / F32(16777215)) - F32(1)


def value_noise(xs, ys, cell, seed):
    """(h, w) float32 value noise at integer texels ``xs`` (w,) and ``ys`` (h,): a lattice every ``cell`` texels."""
    fx = (xs.astype(F32) / F32(cell))[None, :]
    fy = (ys.astype(F32) / F32(cell))[:, None]
    bx, by = np.floor(fx), np.floor(fy)
    ix, iy = bx.astype(np.int32), by.astype(np.int32)
    u, v = fx - bx, fy - by
    su = u * u * (F32(3) - F32(2) * u)
    sv = v * v * (F32(3) - F32(2) * v)
    a, b = _lattice(ix, iy, seed), _lattice(ix + 1, iy, seed)
    c, d = _lattice(ix, iy + 1, seed), _lattice(ix + 1, iy + 1, seed)
    top = a + (b - a) * su
    bottom = c + (d - c) * su
    return top + (bottom - top) * sv


def noise(tile, x0, y0, pos, radius, strength, kind, vec, cell, seed):
    """Add ``vec`` x falloff x value noise (anchored to the map, so overlapping dabs agree)."""
    h, w, c = tile.shape
    inside, k = _weights(x0, y0, w, h, pos, radius, strength, kind)
    n = value_noise(np.arange(x0, x0 + w), np.arange(y0, y0 + h), cell, seed)[inside]
    tile[inside] += operand(vec, c)[None, :] * k[:, None] * n[:, None]


def smooth_full(src, k):
    """Whole-map smooth, a new (H, W, C) array: each texel moves by ``k`` toward its 3x3 mean (clamped borders)."""
    p = np.pad(src, ((1, 1), (1, 1), (0, 0)), mode="edge")
    columns = (p[:-2] + p[1:-1]) + p[2:]
    total = (columns[:, :-2] + columns[:, 1:-1]) + columns[:, 2:]
    return src + (total * (F32(1) / F32(9)) - src) * F32(k)

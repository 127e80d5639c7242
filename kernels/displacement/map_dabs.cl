// Displacement-map edits ([Andrade 2012, §5]), one work item per texel of the dab's footprint tile.
// The footprint is w x h texels from map texel (x0, y0). Its memory starts at element `base` of `map` with rows
// `mem_w` texels apart: the whole map kept on the device (base = (y0 * W + x0) * C, mem_w = W) or an uploaded
// tile (base = 0, mem_w = w). Texel (x, y) of a (H, W, C) float32 map sits at map[y, x].
// Distances are to integer texel coordinates ([Andrade 2012, correction 1]). float4 operands map onto the channels: C = 4: xyzw,
// C = 3: xyz, C = 1: z (the height). Every kernel has a numpy reference in kernels/map_dabs.py that computes
// in the same float32 operations (contraction off), so results agree to the last bit in practice.
#pragma OPENCL FP_CONTRACT OFF

inline float texel_distance(const float2 pos, const int x, const int y)
{
  const float dx = (float)x - pos.x, dy = (float)y - pos.y;
  return sqrt(dx * dx + dy * dy);
}

inline float operand(const float4 v, const int c, const int channels)
{
  if (channels == 1) {
    return v.z;
  }
  return c == 0 ? v.x : (c == 1 ? v.y : (c == 2 ? v.z : v.w));
}

inline float falloff(const float t, const int kind)
{
  // t = d / r in [0, 1): 0 smooth, 1 sphere, 2 linear, 3 sharp, 4 constant
  const float s = 1.0f - t;
  if (kind == 0) {
    return s * s * (3.0f - 2.0f * s);
  }
  if (kind == 1) {
    return sqrt(1.0f - t * t);
  }
  if (kind == 2) {
    return s;
  }
  if (kind == 3) {
    return s * s;
  }
  return 1.0f;
}

// the weight strength * falloff(d / r) of texel (x, y) in *k; false outside the open disc d < r
inline bool brush_weight(const float2 pos, const int x, const int y, const float radius, const float strength,
                         const int kind, float *k)
{
  const float d = texel_distance(pos, x, y);
  if (!(d < radius)) {
    return false;
  }
  *k = strength * falloff(d / radius, kind);
  return true;
}

#define TILE_ARGS                                                                                  \
  __global float *map, const long base, const int mem_w, const int channels, const int x0, const int y0, \
      const int w, const int h

#define TEXEL_SETUP                                             \
  const int gx = get_global_id(0), gy = get_global_id(1);       \
  if (gx >= w || gy >= h) {                                     \
    return;                                                     \
  }                                                             \
  const int x = x0 + gx, y = y0 + gy;                           \
  __global float *t = map + base + ((long)gy * mem_w + gx) * channels;

// Each pointwise dab has its texel's work as an inline function, called by the dab's kernel and by `dabs_batch`.
inline void contact_texel(__global float *t, const int x, const int y, const int channels, const float2 pos,
                          const float depth, const float radius)
{
  if (texel_distance(pos, x, y) < radius) {
    t[channels == 1 ? 0 : 2] -= depth;
  }
}

__kernel void contact(TILE_ARGS, const float2 pos, const float depth, const float radius)
{
  TEXEL_SETUP
  contact_texel(t, x, y, channels, pos, depth, radius);
}

inline void force_texel(__global float *t, const int x, const int y, const int channels, const float2 pos,
                        const float4 f, const float area)
{
  const float dissipation = (area - texel_distance(pos, x, y)) / area;  // = 1 - d / R, exact at [Andrade 2012]'s values
  if (dissipation > 0.0f) {
    for (int c = 0; c < channels; ++c) {
      t[c] += operand(f, c, channels) * dissipation;
    }
  }
}

__kernel void force(TILE_ARGS, const float2 pos, const float4 f, const float area)
{
  TEXEL_SETUP
  force_texel(t, x, y, channels, pos, f, area);
}

__kernel void test(TILE_ARGS, const float4 arg1, const float4 arg2, const float4 arg3, const float4 arg4)
{
  TEXEL_SETUP
  if (texel_distance(arg1.xy, x, y) < arg3.x) {
    for (int c = 0; c < channels; ++c) {
      t[c] += operand(arg2, c, channels);
    }
  }
}

__kernel void morphing(__global const float *a, __global const float *b, __global float *out, const long n,
                       const float time)
{
  const long i = get_global_id(0);
  if (i < n) {
    out[i] = a[i] * (1.0f - time) + b[i] * time;
  }
}

inline void draw_texel(__global float *t, const int x, const int y, const int channels, const float2 pos,
                       const float radius, const float strength, const int kind, const float4 vec)
{
  float k;
  if (brush_weight(pos, x, y, radius, strength, kind, &k)) {
    for (int c = 0; c < channels; ++c) {
      t[c] += operand(vec, c, channels) * k;
    }
  }
}

__kernel void draw(TILE_ARGS, const float2 pos, const float radius, const float strength, const int kind,
                   const float4 vec)
{
  TEXEL_SETUP
  draw_texel(t, x, y, channels, pos, radius, strength, kind, vec);
}


__kernel void flatten(TILE_ARGS, const float2 pos, const float radius, const float strength, const int kind,
                      const float4 target)
{
  TEXEL_SETUP
  float k;
  if (brush_weight(pos, x, y, radius, strength, kind, &k)) {
    for (int c = 0; c < channels; ++c) {
      t[c] += (operand(target, c, channels) - t[c]) * k;
    }
  }
}

// smooth reads a halo tile `src` (hs x ws, origin sx0, sy0, clamped to the map) and writes `tile`
__kernel void smooth(TILE_ARGS, __global const float *src, const int ws, const int hs, const int sx0,
                     const int sy0, const float2 pos, const float radius, const float strength, const int kind)
{
  TEXEL_SETUP
  float k;
  if (brush_weight(pos, x, y, radius, strength, kind, &k)) {
    for (int c = 0; c < channels; ++c) {
      float sum = 0.0f;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int sx = clamp(x + dx - sx0, 0, ws - 1), sy = clamp(y + dy - sy0, 0, hs - 1);
          sum += src[((long)sy * ws + sx) * channels + c];
        }
      }
      t[c] += (sum / 9.0f - t[c]) * k;
    }
  }
}

// stamp: add strength * (bilinear sample of a (sh, sw, channels) stamp map), rotated by `angle` and scaled
__kernel void stamp(TILE_ARGS, __global const float *st, const int sw, const int sh, const float2 pos,
                    const float2 rot, const float scale, const float strength)
{
  TEXEL_SETUP
  const float dx = (float)x - pos.x, dy = (float)y - pos.y;
  const float u = (rot.x * dx + rot.y * dy) / scale + 0.5f * (float)(sw - 1);
  const float v = (rot.x * dy - rot.y * dx) / scale + 0.5f * (float)(sh - 1);
  if (u < 0.0f || v < 0.0f || u > (float)(sw - 1) || v > (float)(sh - 1)) {
    return;
  }
  const int iu = min((int)u, sw - 2 < 0 ? 0 : sw - 2), iv = min((int)v, sh - 2 < 0 ? 0 : sh - 2);
  const float fu = u - (float)iu, fv = v - (float)iv;
  const int iu1 = min(iu + 1, sw - 1), iv1 = min(iv + 1, sh - 1);
  for (int c = 0; c < channels; ++c) {
    const float a = st[((long)iv * sw + iu) * channels + c], b = st[((long)iv * sw + iu1) * channels + c];
    const float p = st[((long)iv1 * sw + iu) * channels + c], q = st[((long)iv1 * sw + iu1) * channels + c];
    const float top = a + (b - a) * fu, bottom = p + (q - p) * fu;
    t[c] += strength * (top + (bottom - top) * fv);
  }
}

// value noise: a lattice of random values in [-1, 1] every `cell` texels, blended with smoothstep weights
inline float lattice(const int ix, const int iy, const uint seed)
{
  uint k = ((uint)ix * 0x8da6b343u) ^ ((uint)iy * 0xd8163841u) ^ (seed * 0xcb1ab31fu);
  k ^= k >> 13;
  k *= 0x5bd1e995u;
  k ^= k >> 15;
  return (float)(k & 0xffffffu) * (2.0f / 16777215.0f) - 1.0f;
}

inline float value_noise(const int x, const int y, const float cell, const uint seed)
{
  const float fx = (float)x / cell, fy = (float)y / cell;
  const float bx = floor(fx), by = floor(fy);
  const int ix = (int)bx, iy = (int)by;
  const float u = fx - bx, v = fy - by;
  const float su = u * u * (3.0f - 2.0f * u), sv = v * v * (3.0f - 2.0f * v);
  const float a = lattice(ix, iy, seed), b = lattice(ix + 1, iy, seed);
  const float c = lattice(ix, iy + 1, seed), d = lattice(ix + 1, iy + 1, seed);
  const float top = a + (b - a) * su, bottom = c + (d - c) * su;
  return top + (bottom - top) * sv;
}

// noise: add vec * strength * falloff * value_noise (map-anchored, so overlapping dabs agree)
inline void noise_texel(__global float *t, const int x, const int y, const int channels, const float2 pos,
                        const float radius, const float strength, const int kind, const float4 vec, const float cell,
                        const uint seed)
{
  float k;
  if (brush_weight(pos, x, y, radius, strength, kind, &k)) {
    const float n = value_noise(x, y, cell, seed);
    for (int c = 0; c < channels; ++c) {
      t[c] += operand(vec, c, channels) * k * n;
    }
  }
}

__kernel void noise(TILE_ARGS, const float2 pos, const float radius, const float strength, const int kind,
                    const float4 vec, const float cell, const uint seed)
{
  TEXEL_SETUP
  noise_texel(t, x, y, channels, pos, radius, strength, kind, vec, cell, seed);
}

// Many pointwise dabs (DRAW, CONTACT, FORCE, NOISE) in one launch over their bounding box
// (kernels/displacement/dab_batch.py). The box is cut into bins of `bin` x `bin` texels, `bins_x` to a row; bin b
// lists the dabs that reach it, in stroke order, at bin_dabs[bin_start[b] .. bin_start[b + 1]). Dab i has 12 floats
// p[12i ..] and 3 ints n[3i ..]: n[3i] its kind (0 DRAW, 1 CONTACT, 2 FORCE, 3 NOISE), then that kind's arguments in
// the order of its kernel (dab_batch.row). A texel's value depends on itself alone, so applying its dabs in order
// gives the bytes of one launch per dab.
__kernel void dabs_batch(TILE_ARGS, __global const float *p, __global const int *n, __global const int *bin_start,
                         __global const int *bin_dabs, const int bin, const int bins_x)
{
  TEXEL_SETUP
  const int b = (gy / bin) * bins_x + gx / bin;
  for (int j = bin_start[b]; j < bin_start[b + 1]; ++j) {
    const int i = bin_dabs[j];
    __global const float *q = p + 12 * (long)i;
    __global const int *m = n + 3 * (long)i;
    const float2 pos = (float2)(q[0], q[1]);
    if (m[0] == 0) {
      draw_texel(t, x, y, channels, pos, q[2], q[3], m[1], (float4)(q[4], q[5], q[6], q[7]));
    } else if (m[0] == 1) {
      contact_texel(t, x, y, channels, pos, q[2], q[3]);
    } else if (m[0] == 2) {
      force_texel(t, x, y, channels, pos, (float4)(q[2], q[3], q[4], q[5]), q[6]);
    } else {
      noise_texel(t, x, y, channels, pos, q[2], q[3], m[1], (float4)(q[4], q[5], q[6], q[7]), q[8], (uint)m[2]);
    }
  }
}

// whole-map smooth (ping-pong: src -> dst). A row is n = W * C floats and a texel's left and right neighbours are
// C floats away, so each work item does 8 consecutive floats of a row with vector loads; borders clamp. Sums run
// columns (up + mid) + down, then (left + centre) + right, as in the numpy reference. A non-finite input texel sets
// `bad` and the host keeps the untouched source.
inline float smooth_one(const __global float *r0, const __global float *r1, const __global float *r2, const int i,
                        const int n, const int C, const float k)
{
  const int im = i - C < 0 ? i : i - C, ip = i + C >= n ? i : i + C;
  const float left = (r0[im] + r1[im]) + r2[im], centre = (r0[i] + r1[i]) + r2[i];
  const float right = (r0[ip] + r1[ip]) + r2[ip];
  return r1[i] + (((left + centre) + right) * (1.0f / 9.0f) - r1[i]) * k;
}

__kernel void smooth_all(__global const float *src, __global float *dst, __global int *bad, const int n, const int H,
                         const int C, const float k)
{
  const int y = get_global_id(1), i = get_global_id(0) * 8;
  if (y >= H || i >= n) {
    return;
  }
  const long row = n;
  const __global float *r0 = src + max(y - 1, 0) * row, *r1 = src + y * row, *r2 = src + min(y + 1, H - 1) * row;
  __global float *out = dst + y * row;
  if (i >= C && i + 8 + C <= n) {
    const float8 a = (vload8(0, r0 + i - C) + vload8(0, r1 + i - C)) + vload8(0, r2 + i - C);
    const float8 v = vload8(0, r1 + i);
    const float8 b = (vload8(0, r0 + i) + v) + vload8(0, r2 + i);
    const float8 c = (vload8(0, r0 + i + C) + vload8(0, r1 + i + C)) + vload8(0, r2 + i + C);
    vstore8(v + (((a + b) + c) * (1.0f / 9.0f) - v) * k, 0, out + i);
    if (any(isnan(v)) || any(isinf(v))) {
      bad[0] = 1;
    }
  } else {
    for (int j = i; j < min(i + 8, n); ++j) {
      out[j] = smooth_one(r0, r1, r2, j, n, C, k);
      if (isnan(r1[j]) || isinf(r1[j])) {
        bad[0] = 1;
      }
    }
  }
}

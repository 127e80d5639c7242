// Rotation-minimising frames, one work item per curve, walking its points in order (double reflection,
// Wang et al. 2008). The numpy reference is kernels.frames.rotation_minimizing_frames (same tangents, same
// first normal, same seam correction and tilt; it composes the same steps as quaternions).
// pts: (P, 3) double; offsets: (C + 1) long; cyclic: (C) uchar; tilt: (P) double; arc: (P) double arc length
// from the curve start; total: (C) double curve length. Out: t, n, b: (P, 3) float.
#pragma OPENCL EXTENSION cl_khr_fp64 : enable

inline double3 ld(__global const double *a, long i) { return (double3)(a[3 * i], a[3 * i + 1], a[3 * i + 2]); }
inline void st(__global float *a, long i, double3 v) { a[3 * i] = (float)v.x; a[3 * i + 1] = (float)v.y; a[3 * i + 2] = (float)v.z; }
inline double3 unit_or_zero(double3 v) { double l = length(v); return l > 1e-300 ? v / l : (double3)(0.0); }

// the tangent from the unit directions into and out of a point (zero where there is none), as `tangent` forms it
inline double3 tangent_of(double3 din, double3 dout, int has_next)
{
  double3 sum = din + dout;
  double l = length(sum);
  if (l < 1e-9) {
    return has_next ? dout : din;
  }
  return sum / l;
}

inline double3 tangent(__global const double *pts, long s, long e, uchar cyc, long i)
{
  int has_prev = (i > s) || cyc;
  int has_next = (i < e - 1) || cyc;
  long ip = (i > s) ? i - 1 : e - 1;
  long in = (i < e - 1) ? i + 1 : s;
  double3 p = ld(pts, i);
  double3 din = has_prev ? unit_or_zero(p - ld(pts, ip)) : (double3)(0.0);
  double3 dout = has_next ? unit_or_zero(ld(pts, in) - p) : (double3)(0.0);
  return tangent_of(din, dout, has_next);
}

inline double3 perpendicular(double3 t)
{
  double3 a = fabs(t);
  double3 axis = (a.x <= a.y && a.x <= a.z) ? (double3)(1, 0, 0) : ((a.y <= a.z) ? (double3)(0, 1, 0) : (double3)(0, 0, 1));
  return normalize(axis - dot(axis, t) * t);
}

// carry frame vector r from tangent t0 to t1 across the unit chord a = unit_or_zero(x1 - x0)
inline double3 carry_along(double3 a, double3 t0, double3 r, double3 t1)
{
  double3 rl = r - 2.0 * dot(a, r) * a;
  double3 tl = t0 - 2.0 * dot(a, t0) * a;
  double3 v2 = t1 - tl;
  double c2 = length(v2);
  double3 b = c2 < 1e-12 ? t1 : v2 / c2;
  return rl - 2.0 * dot(b, rl) * b;
}

// carry frame vector r from (x0, t0) to (x1, t1)
inline double3 carry(double3 x0, double3 t0, double3 r, double3 x1, double3 t1)
{
  return carry_along(unit_or_zero(x1 - x0), t0, r, t1);
}

__kernel void tube_frames(__global const double *pts, __global const long *offsets, __global const uchar *cyclic,
                          __global const double *tilt, __global const double *arc, __global const double *total,
                          __global float *t_out, __global float *n_out, __global float *b_out, const int n_curves)
{
  const int c = get_global_id(0);
  if (c >= n_curves) {
    return;
  }
  const long s = offsets[c], e = offsets[c + 1];
  if (e <= s) {
    return;
  }
  const uchar cyc = cyclic[c] && (e - s >= 3);
  double3 t = tangent(pts, s, e, cyc, s);
  double3 r = perpendicular(t);
  double3 x = ld(pts, s);
  st(t_out, s, t);
  st(n_out, s, r);
  // the unit direction of each segment is formed once: it is the direction out of one point, the direction into
  // the next (both of `tangent`) and the carry's reflection axis, all the same expression of the same two points
  double3 dout = unit_or_zero(ld(pts, s + 1 < e ? s + 1 : s) - x);
  for (long i = s + 1; i < e; ++i) {
    double3 x1 = ld(pts, i);
    const int has_next = (i < e - 1) || cyc;
    double3 din = dout;
    dout = has_next ? unit_or_zero(ld(pts, i < e - 1 ? i + 1 : s) - x1) : (double3)(0.0);
    double3 t1 = tangent_of(din, dout, has_next);
    r = carry_along(din, t, r, t1);
    r = normalize(r - dot(r, t1) * t1);
    st(t_out, i, t1);
    st(n_out, i, r);
    x = x1;
    t = t1;
  }
  double rate = 0.0;
  if (cyc) {
    double3 tf = tangent(pts, s, e, cyc, s);
    double3 r0 = perpendicular(tf);
    double3 r_end = carry(x, t, r, ld(pts, s), tf);
    r_end = normalize(r_end - dot(r_end, tf) * tf);
    double phi = atan2(dot(cross(r_end, r0), tf), dot(r_end, r0));
    rate = phi / fmax(total[c], 1e-24);
  }
  for (long i = s; i < e; ++i) {
    double3 ti = (double3)(t_out[3 * i], t_out[3 * i + 1], t_out[3 * i + 2]);
    double3 ri = (double3)(n_out[3 * i], n_out[3 * i + 1], n_out[3 * i + 2]);
    double angle = tilt[i] + rate * arc[i];
    if (angle != 0.0) {
      ri = cos(angle) * ri + sin(angle) * cross(ti, ri);
    }
    st(n_out, i, ri);
    st(b_out, i, cross(ti, ri));
  }
}

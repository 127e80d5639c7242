/* Parameter in [0, 1] of point j of an edge of n segments at clamped level f: kernels/partition.py point_params
 * (EQUAL, or FRACTIONAL_EVEN when `fractional`). A palindrome: computed from the nearer end, then mirrored. */
float param(float f, float n, float j, bool fractional)
{
  float jm = min(j, n - j);
  float h;
  if (!fractional) {
    h = jm / n;
  }
  else {
    float long_len = n > 2.0 ? (2.0 * n - 2.0 - f) / (n * (n - 2.0)) : 0.5;
    h = (2.0 * jm == n) ? 0.5 : jm * long_len;
  }
  return 2.0 * j <= n ? h : 1.0 - h;
}

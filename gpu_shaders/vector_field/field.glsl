/* The steady fields of kernels/vector_field/fields.py in float32: field_kind 0 ABC (slice_z, speed), 1 VORTEX
 * (speed), 2 GRID (vectors in the rg of `grid`, grid_size texels, bilinear, clamped). Domain: the unit square. */

vec2 field_at(vec2 p)
{
  if (field_kind == 0) {
    const float TWO_PI = 6.283185307179586;
    float a = sqrt(3.0);
    float b = sqrt(2.0);
    float u = a * sin(slice_z) + cos(TWO_PI * p.y);
    float v = b * sin(TWO_PI * p.x) + a * cos(slice_z);
    return speed * vec2(u, v) / TWO_PI;
  }
  if (field_kind == 1) {
    vec2 d = p - vec2(0.5);
    float w = 0.05 / (dot(d, d) + 0.01);
    return speed * vec2(-d.y, d.x) * w;
  }
  vec2 g = clamp(p, 0.0, 1.0) * vec2(grid_size - 1);
  ivec2 i0 = min(ivec2(floor(g)), grid_size - 2);
  vec2 f = g - vec2(i0);
  vec2 v00 = texelFetch(grid, i0, 0).xy;
  vec2 v10 = texelFetch(grid, i0 + ivec2(1, 0), 0).xy;
  vec2 v01 = texelFetch(grid, i0 + ivec2(0, 1), 0).xy;
  vec2 v11 = texelFetch(grid, i0 + ivec2(1, 1), 0).xy;
  return (v00 * (1.0 - f.x) + v10 * f.x) * (1.0 - f.y) + (v01 * (1.0 - f.x) + v11 * f.x) * f.y;
}

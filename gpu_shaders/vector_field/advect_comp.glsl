/* One explicit Euler step (eq. 5.1) of every seed point: x + h f(x), from `points_in` into `points_out` (texel i at
 * (i % tex_width, i / tex_width): x, y, noise value, 0). Ping-pong: the host swaps the two between steps. */
void main()
{
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  int i = texel.y * tex_width + texel.x;
  if (texel.x >= tex_width || i >= count) {
    return;
  }
  vec4 p = texelFetch(points_in, texel, 0);
  imageStore(points_out, texel, vec4(p.xy + step_size * field_at(p.xy), p.z, 0.0));
}

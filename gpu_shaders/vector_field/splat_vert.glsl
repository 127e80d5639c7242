/* Splat seed point `id` where it is now: a one-pixel point at its domain position, carrying its noise value. */
void main()
{
  int i = int(id);
  vec4 p = texelFetch(points, ivec2(i % tex_width, i / tex_width), 0);
  value = p.z;
  gl_Position = vec4(p.xy * 2.0 - 1.0, 0.0, 1.0);
  gl_PointSize = 1.0;
}

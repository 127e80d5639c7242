/* The board's quad: corner `corner` in texel units of the board (0..width, 0..height) on its plane. */
void main()
{
  texel = corner;
  vec3 world = origin + corner.x * axis_a + corner.y * axis_b;
  gl_Position = shading.view_projection * vec4(world, 1.0);
}

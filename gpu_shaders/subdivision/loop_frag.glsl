void main()
{
  float lit = shading.lit_range.x + shading.lit_range.y * shade;
  frag_color = vec4(vertex_color.rgb * lit, 1.0);
}

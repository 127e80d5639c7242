void main()
{
  float lit = lit_range.x + lit_range.y * shade;
  frag_color = vec4(vertex_color.rgb * lit, 1.0);
}

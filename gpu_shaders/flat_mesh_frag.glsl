void main()
{
  float lit = lit_range.x + lit_range.y * shade;
  frag_color = vec4(color.rgb * lit, color.a);
}

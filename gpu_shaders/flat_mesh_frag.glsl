void main()
{
  float lit = shading.lit_range.x + shading.lit_range.y * shade;
  frag_color = vec4(shading.color.rgb * lit, shading.color.a);
}

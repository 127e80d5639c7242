/* Every preview's colour, from the base colour (shading.color, or the vertex colour where the shader has one and
 * light_dir.w says so): with studio lighting on (lit_range.z, `offscreen.ViewLighting`), lit as Solid mode lights
 * Blender's own objects from the view-space normal (its studio lights, or its MatCap where lit_range.z is 2), both
 * sides lit; otherwise the check shade (a headlight mixed
 * by lit_range.xy, or the flat colour). Output is linear: the viewport's overlay buffer encodes it. */
void main()
{
#ifdef TESSERA_VERTEX_COLOR
  vec3 base = shading.light_dir.w > 0.5 ? vertex_color.rgb : shading.color.rgb;
#else
  vec3 base = shading.color.rgb;
#endif
  if (shading.lit_range.z > 0.5) {
    vec3 N = normalize(view_normal);
    N = gl_FrontFacing ? N : -N;
    vec3 I = shading.lit_range.w > 0.5 ? vec3(0.0, 0.0, 1.0) : normalize(-view_position);
    vec3 lit = shading.lit_range.z > 1.5 ? matcap_light(base, N, I) :
                                           solid_light(base, shading.material.x, shading.material.y, N, I);
    frag_color = vec4(lit, shading.color.a);
    return;
  }
  float lit = shading.lit_range.x + shading.lit_range.y * shade;
  frag_color = vec4(base * lit, shading.color.a);
}

/* Every preview's colour: with studio lighting on (lit_range.z, `offscreen.ViewLighting`), lit as Solid mode lights
 * Blender's own objects from the view-space normal, both sides lit; otherwise the check shade (a headlight mixed
 * by lit_range.xy, or the flat colour). Output is linear: the viewport's overlay buffer encodes it. */
void main()
{
  if (shading.lit_range.z > 0.5) {
    vec3 N = normalize(view_normal);
    N = gl_FrontFacing ? N : -N;
    vec3 I = shading.lit_range.w > 0.5 ? vec3(0.0, 0.0, 1.0) : normalize(-view_position);
    frag_color = vec4(solid_light(shading.color.rgb, shading.material.x, shading.material.y, N, I),
                      shading.color.a);
    return;
  }
  float lit = shading.lit_range.x + shading.lit_range.y * shade;
  frag_color = vec4(shading.color.rgb * lit, shading.color.a);
}

/* Tube preview ([Nunes 2011, §4.4], without a tessellation stage): one instance per patch of up to 63 segments,
 * one instanced ring pattern per side count. Section s occupies texels 3s..3s+2 of `sections` (row-major,
 * `tex_width` wide): (centre, radius), (N, 0), (B, 0). Patch p is texel p of `patches`: (first section,
 * segments, 0, 0). Pattern vertex `ij` = (section within the patch, side). */

vec4 fetch(sampler2D tex, int i)
{
  return texelFetch(tex, ivec2(i % tex_width, i / tex_width), 0);
}

void main()
{
  vec4 patch_info = fetch(patches, gl_InstanceID);
  int k = min(int(ij.x), int(patch_info.y));
  int s = int(patch_info.x) + k;
  vec4 centre = fetch(sections, 3 * s);
  vec3 N = fetch(sections, 3 * s + 1).xyz;
  vec3 B = fetch(sections, 3 * s + 2).xyz;
  float theta = 6.283185307179586 * ij.y / sides;
  vec3 radial = cos(theta) * N + sin(theta) * B;
  float radius = centre.w;
  if (clamp_radius.x > 0.0) {
    /* world size of one pixel at the centre's depth ([Nunes 2011] eq. 4-3..4-5), kept as the ring's inscribed radius */
    vec4 clip = shading.view_projection * vec4(centre.xyz, 1.0);
    if (clip.w > 0.0) {
      float z = clip.z / clip.w;
      vec4 a = inverse_view_projection * vec4(0.0, 0.0, z, 1.0);
      vec4 b = inverse_view_projection * vec4(2.0 / viewport_width, 0.0, z, 1.0);
      float pixel = length(b.xyz / b.w - a.xyz / a.w) / cos(3.141592653589793 / sides);
      if (clamp_radius.y > 0.0) {
        pixel = min(pixel, clamp_radius.y);
      }
      radius = max(radius, pixel);
    }
  }
  vec3 world = centre.xyz + radius * radial;
  gl_Position = shading.view_projection * vec4(world, 1.0);
  shade = abs(dot(radial, shading.light_dir.xyz));
  view_normal = mat3(shading.normal_matrix) * radial;
  view_position = (shading.model_view * vec4(world, 1.0)).xyz;
}

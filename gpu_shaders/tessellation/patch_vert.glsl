/* PN / Phong / linear preview without a tessellation stage: one instanced pattern per class (`counts`: n0, n1,
 * n2, m), one instance per input triangle. Instance i reads texels 2i, 2i+1 of `instances` (levels; triangle
 * id) and the triangle's control texels; `evaluate` is patch_eval.glsl. Optional displacement (`displace`
 * 1 height along the normal, 2 vector in object space, 3 vector in tangent space) from `displacement` at the
 * interpolated UV: (value - mid_strength.x) * mid_strength.y, the value of a height map being the mean of R, G,
 * B. Tangent space as kernels/tangent_space.py: the interpolated tangent made orthogonal to the normal, the
 * bitangent sign x (normal x tangent). */

/* Bilinear lookup with clamped edges (Blender's Linear + Extend), by texel fetches: the same at every vertex
 * whatever the texture's sampler state and mipmaps. */
vec3 sample_map(vec2 uv)
{
  ivec2 size = textureSize(displacement, 0);
  vec2 x = uv * vec2(size) - 0.5;
  vec2 x0 = floor(x);
  vec2 f = x - x0;
  ivec2 lo = clamp(ivec2(x0), ivec2(0), size - 1), hi = clamp(ivec2(x0) + 1, ivec2(0), size - 1);
  vec3 top = mix(texelFetch(displacement, lo, 0).rgb, texelFetch(displacement, ivec2(hi.x, lo.y), 0).rgb, f.x);
  vec3 bottom = mix(texelFetch(displacement, ivec2(lo.x, hi.y), 0).rgb, texelFetch(displacement, hi, 0).rgb, f.x);
  return mix(top, bottom, f.y);
}

vec4 instance_row(int i)
{
  return texelFetch(instances, ivec2(i % tex_width, i / tex_width), 0);
}

void main()
{
  vec4 lev = instance_row(2 * gl_InstanceID);
  int tri = int(instance_row(2 * gl_InstanceID + 1).x);
  vec3 pos, nor, bary;
  evaluate(tri, code, lev, counts, true, pos, nor, bary);
  if (displace != 0) {
    vec3 value = sample_map(uv_at(tri, bary));
    if (displace == 1) {
      pos += nor * ((value.r + value.g + value.b) / 3.0 - mid_strength.x) * mid_strength.y;
    }
    else if (displace == 2) {
      pos += (value - vec3(mid_strength.x)) * mid_strength.y;
    }
    else {
      vec4 tg = tangent_at(tri, bary);
      vec3 t = safe_normalize(tg.xyz - nor * dot(nor, tg.xyz));
      vec3 bt = (tg.w < 0.0 ? -1.0 : 1.0) * cross(nor, t);
      vec3 d = (value - vec3(mid_strength.x)) * mid_strength.y;
      pos += d.x * t + d.y * bt + d.z * nor;
    }
  }
  gl_Position = shading.view_projection * vec4(pos, 1.0);
  shade = abs(dot(nor, shading.light_dir.xyz));
  view_normal = mat3(shading.normal_matrix) * nor;
  view_position = (shading.model_view * vec4(pos, 1.0)).xyz;
}

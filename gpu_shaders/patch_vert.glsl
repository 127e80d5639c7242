/* PN / Phong / linear preview without a tessellation stage: one instanced pattern per class (`counts`: n0, n1,
 * n2, m), one instance per input triangle. Instance i reads texels 2i, 2i+1 of `instances` (levels; triangle
 * id) and the triangle's control texels; `evaluate` is patch_eval.glsl. Optional displacement (`displace`
 * 1 height along the normal, 2 vector in object space) from `displacement` at the interpolated UV:
 * (value - mid_strength.x) * mid_strength.y, the value of a height map being the mean of R, G, B. */

vec4 instance_row(int i)
{
  return texelFetch(instances, ivec2(i % tex_width, i / tex_width), 0);
}

void main()
{
  vec4 lev = instance_row(2 * gl_InstanceID);
  int tri = int(instance_row(2 * gl_InstanceID + 1).x);
  vec3 pos, nor;
  vec2 uv;
  evaluate(tri, code, lev, counts, true, pos, nor, uv);
  if (displace != 0) {
    vec3 value = texture(displacement, uv).rgb;
    if (displace == 1) {
      pos += nor * ((value.r + value.g + value.b) / 3.0 - mid_strength.x) * mid_strength.y;
    }
    else {
      pos += (value - vec3(mid_strength.x)) * mid_strength.y;
    }
  }
  gl_Position = view_projection * vec4(pos, 1.0);
  shade = abs(dot(nor, light_dir));
}

/* PN / Phong / linear preview without a tessellation stage: one instanced pattern per class (`counts`: n0, n1,
 * n2, m), one instance per input triangle. Instance i reads texels 2i, 2i+1 of `instances` (levels; triangle
 * id) and the triangle's control texels; `evaluate` is patch_eval.glsl. Optional displacement (`displace`
 * 1 height along the normal, 2 vector in object space, 3 vector in tangent space) from `displacement` at the
 * interpolated UV: (value - mid_strength.x) * mid_strength.y, the value of a height map being the mean of R, G,
 * B. Tangent space as kernels/tangent_space.py: the interpolated tangent made orthogonal to the normal, the
 * bitangent sign x (normal x tangent). The displaced surface is shaded with its own normal (`displaced_normal`). */

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

/* The displacement's object-space offset at `uv`, in the frame of the vertex (normal; tangent and bitangent for
 * tangent-space maps). */
vec3 offset_at(vec2 uv, vec3 nor, vec3 t, vec3 bt)
{
  vec3 value = sample_map(uv);
  if (displace == 1) {
    return nor * (((value.r + value.g + value.b) / 3.0 - mid_strength.x) * mid_strength.y);
  }
  vec3 d = (value - vec3(mid_strength.x)) * mid_strength.y;
  return displace == 2 ? d : d.x * t + d.y * bt + d.z * nor;
}

/* The undisplaced surface at barycentric `b` of `tri` (any b: the patch's polynomial continues past its edges). */
void surface_at(int tri, vec3 b, out vec3 pos, out vec3 nor)
{
  vec3 p[3], n[3], s[3];
  vec3 a;
  for (int i = 0; i < 3; i++) {
    vec4 r = control_row(tri, i);
    p[i] = r.xyz;
    a[i] = r.w;
    n[i] = control_row(tri, 3 + i).xyz;
    s[i] = control_row(tri, 6 + i).xyz;
  }
  pos = face_position(p[0], p[1], p[2], n[0], n[1], n[2], a, b);
  nor = face_normal(p[0], p[1], p[2], s[0], s[1], s[2], b);
}

/* The tangent frame of a tangent-space map at barycentric `b`: tangent and bitangent orthogonal to `nor`. */
void frame_at(int tri, vec3 b, vec3 nor, out vec3 t, out vec3 bt)
{
  vec4 tg = tangent_at(tri, b);
  t = safe_normalize(tg.xyz - nor * dot(nor, tg.xyz));
  bt = (tg.w < 0.0 ? -1.0 : 1.0) * cross(nor, t);
}

/* The displaced surface's point at barycentric `b`: the surface there moved by the map there, in the frame there. */
vec3 displaced_at(int tri, vec3 b)
{
  vec3 pos, nor, t = vec3(0.0), bt = vec3(0.0);
  surface_at(tri, b, pos, nor);
  if (displace == 3) {
    frame_at(tri, b, nor, t, bt);
  }
  return pos + offset_at(uv_at(tri, b), nor, t, bt);
}

/* The normal of the displaced surface at barycentric `b`: the cross product of its central differences along the
 * triangle's two edge directions, about one map texel apart, facing as the undisplaced normal `nor` faces the
 * triangle's winding. `nor` where the differences are degenerate. */
vec3 displaced_normal(int tri, vec3 b, vec3 nor)
{
  vec2 w0 = uv_at(tri, vec3(1.0, 0.0, 0.0));
  float span = max(length(uv_at(tri, vec3(0.0, 1.0, 0.0)) - w0), length(uv_at(tri, vec3(0.0, 0.0, 1.0)) - w0));
  ivec2 size = textureSize(displacement, 0);
  float h = clamp(1.0 / (float(max(size.x, size.y)) * max(span, 1e-8)), 1e-4, 0.05);
  vec3 d1 = vec3(-h, h, 0.0), d2 = vec3(-h, 0.0, h);
  vec3 a1 = displaced_at(tri, b + d1) - displaced_at(tri, b - d1);
  vec3 a2 = displaced_at(tri, b + d2) - displaced_at(tri, b - d2);
  vec3 winding = cross(control_row(tri, 1).xyz - control_row(tri, 0).xyz,
                       control_row(tri, 2).xyz - control_row(tri, 0).xyz);
  vec3 n = cross(a1, a2) * (dot(winding, nor) < 0.0 ? -1.0 : 1.0);
  return dot(n, n) > 0.0 ? normalize(n) : nor;
}

void main()
{
  vec4 lev = instance_row(2 * gl_InstanceID);
  int tri = int(instance_row(2 * gl_InstanceID + 1).x);
  vec3 pos, nor, bary;
  evaluate(tri, code, lev, counts, true, pos, nor, bary);
  if (displace != 0) {
    vec3 t = vec3(0.0), bt = vec3(0.0);
    if (displace == 3) {
      frame_at(tri, bary, nor, t, bt);
    }
    pos += offset_at(uv_at(tri, bary), nor, t, bt);
    nor = displaced_normal(tri, bary, nor);
  }
  gl_Position = shading.view_projection * vec4(pos, 1.0);
  shade = abs(dot(nor, shading.light_dir.xyz));
  view_normal = mat3(shading.normal_matrix) * nor;
  view_position = (shading.model_view * vec4(pos, 1.0)).xyz;
}

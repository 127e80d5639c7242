/* Terrain preview ([Nunes 2011, §5.6], without a tessellation stage): one instanced pattern per tile class
 * (four edge segment counts `edge_counts` and the inner counts along x and y `inner_counts`), one instance per
 * tile. Instance t reads texels 3t..3t+2 of `tiles`: (x0, y0, x1, y1) in samples, the four edge levels, (inner
 * level along x, along y, 0, 0). Pattern vertex `code` = (kind, a, b): 0 corner (a, b); 1-4 point a of side BOTTOM, RIGHT,
 * TOP, LEFT; 5 inner grid point (a, b). Heights are sampled bilinearly from `heights` (R32F, one texel per
 * sample, `height_stride` samples per texel) in the vertex shader. `param` is partition.glsl. */

vec4 fetch_tile(int i)
{
  return texelFetch(tiles, ivec2(i % tex_width, i / tex_width), 0);
}

float height_at(vec2 s)
{
  vec2 t = s / height_stride;
  ivec2 size = textureSize(heights, 0);
  t = clamp(t, vec2(0.0), vec2(size - 1));
  ivec2 i0 = min(ivec2(floor(t)), size - 2);
  vec2 f = t - vec2(i0);
  float h00 = texelFetch(heights, i0, 0).r, h10 = texelFetch(heights, i0 + ivec2(1, 0), 0).r;
  float h01 = texelFetch(heights, i0 + ivec2(0, 1), 0).r, h11 = texelFetch(heights, i0 + ivec2(1, 1), 0).r;
  return mix(mix(h00, h10, f.x), mix(h01, h11, f.x), f.y);
}

void main()
{
  vec4 rect = fetch_tile(3 * gl_InstanceID);
  vec4 lev = fetch_tile(3 * gl_InstanceID + 1);
  vec2 f_in = fetch_tile(3 * gl_InstanceID + 2).xy;
  bool frac = fractional != 0;
  int kind = int(code.x);
  vec2 uv;
  if (kind == 0) {
    uv = code.yz;
  }
  else if (kind == 1) {
    uv = vec2(param(lev.x, edge_counts.x, code.y, frac), 0.0);
  }
  else if (kind == 2) {
    uv = vec2(1.0, param(lev.y, edge_counts.y, code.y, frac));
  }
  else if (kind == 3) {
    uv = vec2(param(lev.z, edge_counts.z, code.y, frac), 1.0);
  }
  else if (kind == 4) {
    uv = vec2(0.0, param(lev.w, edge_counts.w, code.y, frac));
  }
  else {
    uv = vec2(param(f_in.x, inner_counts.x, code.y, frac), param(f_in.y, inner_counts.y, code.z, frac));
  }
  vec2 s = rect.xy + uv * (rect.zw - rect.xy);
  float z = height_at(s);
  vec3 world = vec3((s - grid.xy) * grid.zw, z);
  gl_Position = shading.view_projection * vec4(world, 1.0);
  /* central differences over height_stride samples, each scaled by the other axis' texel (x: grid.z, y: grid.w) */
  vec3 n = normalize(vec3((height_at(s - vec2(height_stride, 0.0)) - height_at(s + vec2(height_stride, 0.0))) * grid.w,
                          (height_at(s - vec2(0.0, height_stride)) - height_at(s + vec2(0.0, height_stride))) * grid.z,
                          2.0 * grid.z * grid.w * height_stride));
  shade = abs(dot(n, shading.light_dir.xyz));
  view_normal = mat3(shading.normal_matrix) * n;
  view_position = (shading.model_view * vec4(world, 1.0)).xyz;
}

/* Compute apply: evaluate every welded output vertex once (kernels/patch_instances.py vertex_rows: code,
 * owner levels, owner segment counts, owner id) with the preview's `evaluate`, into `out_positions` and
 * `out_normals` (RGBA32F, `tex_width` wide, vertex v at (v % tex_width, v / tex_width)). */

vec4 vertex_row(int i)
{
  return texelFetch(vertices, ivec2(i % tex_width, i / tex_width), 0);
}

void main()
{
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  int v = texel.y * tex_width + texel.x;
  if (texel.x >= tex_width || v >= vertex_count) {
    return;
  }
  vec3 pos, nor, bary;
  evaluate(int(vertex_row(4 * v + 3).x), vertex_row(4 * v), vertex_row(4 * v + 1), vertex_row(4 * v + 2), false,
           pos, nor, bary);
  imageStore(out_positions, texel, vec4(pos, 1.0));
  imageStore(out_normals, texel, vec4(nor, 0.0));
}

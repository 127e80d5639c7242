/* Loop subdivision on the GPU, one invocation per coarse triangle (kernels/subdivision/loop_stencils.py, whose
 * `apply` is the reference): the triangle's stencil (rows x width_p weights) times its packed 1-ring's points,
 * written to every vertex of its sub-triangles (out_positions, vertex v at (v % tex_width, v / tex_width)).
 * Scalars (ids as exact floats, weights) are packed four to an RGBA32F texel. */

float scalar(sampler2D tex, int i)
{
  int t = i / 4;
  return texelFetch(tex, ivec2(t % tex_width, t / tex_width), 0)[i % 4];
}

void main()
{
  int f = int(gl_GlobalInvocationID.x);
  if (f >= face_count) {
    return;
  }
  int s = int(scalar(stencil, f));
  for (int k = 0; k < rows; ++k) {
    vec3 sum = vec3(0.0);
    for (int i = 0; i < width_p; ++i) {
      int p = int(scalar(patch_ids, f * width_p + i));
      if (p < 0) {
        break;
      }
      sum += scalar(weights, (s * rows + k) * width_p + i) * texelFetch(points, ivec2(p % tex_width, p / tex_width), 0).xyz;
    }
    int v = int(scalar(outputs, f * rows + k));
    imageStore(out_positions, ivec2(v % tex_width, v / tex_width), vec4(sum, 1.0));
  }
}

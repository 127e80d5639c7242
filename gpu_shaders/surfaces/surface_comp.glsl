/* Evaluate every vertex of `instance_count` instances of the domain pattern (`domain_count` vertices each, domain
 * vertex k at (k / (factor + 1), k % (factor + 1)) / factor) into `out_positions`, vertex i at
 * (i % tex_width, i / tex_width): what the preview's vertex shader draws. */
void main()
{
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  int i = texel.y * tex_width + texel.x;
  if (texel.x >= tex_width || i >= instance_count * domain_count) {
    return;
  }
  int instance = i / domain_count;
  int k = i % domain_count;
  vec2 uv = vec2(float(k / (factor + 1)), float(k % (factor + 1))) / float(factor);
  vec3 p = control_point(instance).xyz + surface_point(kind, uv, shape);
  imageStore(out_positions, texel, vec4(p, 1.0));
}

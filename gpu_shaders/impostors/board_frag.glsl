/* A nailboard texel: the offset map (the pre-warp's source address, -1 in holes: no NaN test, which Metal's fast
 * math may fold away) picks the source texel by a
 * dependent lookup, nearest; its colour is written as it is (or lit from the normal map), and its depth is the depth
 * of the source texel's relief point, so the board intersects and occludes like the object. With `lit` 2 every texel
 * is the flat `shading.color` (a selection outline's mask). */
void main()
{
  ivec2 here = ivec2(floor(texel));
  vec2 source = texelFetch(offsets, here, 0).xy;
  if (source.x < 0.0) { /* a hole */
    discard;
  }
  ivec2 s = ivec2(floor(source));
  vec4 colour = texelFetch(colours, s, 0);
  float d = texelFetch(displacement, s, 0).r;
  vec3 world = origin + source.x * axis_a + source.y * axis_b + d * normal_f;
  vec4 clip = shading.view_projection * vec4(world, 1.0);
  gl_FragDepth = 0.5 * (clip.z / clip.w) + 0.5;
  if (lit == 2) { /* a mask: the flat colour */
    frag_color = shading.color;
    return;
  }
  if (lit != 0) {
    vec3 n = normalize(texelFetch(normals, s, 0).xyz);
    colour.rgb *= 0.25 + 0.75 * abs(dot(n, shading.light_dir.xyz));
  }
  frag_color = colour;
}

/* Blender's selection outline around what previews drew instead of their objects. `ids` holds, per pixel of the
 * region, the nearest previewed object's outline id in alpha (0 none, 0.5 selected, 1 active) and `depths` its depth.
 * A pixel is on the outline where one of its four neighbours (one pixel away, or two where the outline is thick) holds
 * another id, but not all four (a lone pixel), on both sides of the silhouette as Blender draws it; it takes the
 * colour and depth of the object it borders. The depth test against the scene's depth then keeps the visible part
 * (this pass, alpha 1) or the occluded part (the second pass, faint), as Blender fades an outline behind another
 * object. */

float outline_id(ivec2 p, ivec2 size)
{
  if (any(lessThan(p, ivec2(0))) || any(greaterThanEqual(p, size))) {
    return 0.0;
  }
  return floor(texelFetch(ids, p, 0).a * 2.0 + 0.5);
}

void look(ivec2 q, ivec2 size, float ref, inout float colour_id, inout ivec2 depth_at, inout int edges)
{
  float id = outline_id(q, size);
  if (colour_id < 0.5 && id > 0.5) { /* the outline bleeds onto the background */
    colour_id = id;
    depth_at = q;
  }
  edges += id != ref ? 1 : 0;
}

void main()
{
  ivec2 size = textureSize(ids, 0);
  ivec2 p = ivec2(gl_FragCoord.xy);
  float ref = outline_id(p, size);
  float colour_id = ref;
  ivec2 depth_at = p;
  int edges = 0;
  int reach = thick != 0 ? 2 : 1;
  for (int r = 1; r <= reach && edges == 0; r++) {
    look(p + ivec2(r, 0), size, ref, colour_id, depth_at, edges);
    look(p - ivec2(r, 0), size, ref, colour_id, depth_at, edges);
    look(p + ivec2(0, r), size, ref, colour_id, depth_at, edges);
    look(p - ivec2(0, r), size, ref, colour_id, depth_at, edges);
  }
  if (edges == 0 || edges == 4 || colour_id < 0.5) {
    discard;
  }
  gl_FragDepth = max(texelFetch(depths, depth_at, 0).r - depth_bias, 0.0);
  vec4 colour = colour_id > 1.5 ? active_color : selected_color;
  frag_color = vec4(colour.rgb, colour.a * alpha);
}

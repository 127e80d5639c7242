/* A Loop-subdivided mesh with vertex colours: object-space position, normal and colour in; a headlight shade
 * from the view-space normal, both sides lit. */
void main()
{
  gl_Position = shading.view_projection * vec4(pos, 1.0);
  vec3 n = normalize(mat3(model_view) * nor);
  shade = abs(n.z);
  vertex_color = col;
}

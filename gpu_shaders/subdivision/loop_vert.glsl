/* A Loop-subdivided mesh with vertex colours: object-space position, normal and colour in; the view-space normal and
 * position for the shared fragment stage (`offscreen.shaded_create_info`), a light's shade for the check shade. */
void main()
{
  gl_Position = shading.view_projection * vec4(pos, 1.0);
  view_normal = mat3(shading.normal_matrix) * nor;
  view_position = (shading.model_view * vec4(pos, 1.0)).xyz;
  shade = abs(dot(normalize(nor), shading.light_dir.xyz));
  vertex_color = col;
}

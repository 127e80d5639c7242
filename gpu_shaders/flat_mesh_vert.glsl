/* Flat-lit mesh for offscreen checks: world-space position and normal in, clip-space out. */
void main()
{
  gl_Position = shading.view_projection * vec4(pos, 1.0);
  shade = abs(dot(normalize(nor), shading.light_dir.xyz));
  view_normal = mat3(shading.normal_matrix) * nor;
  view_position = (shading.model_view * vec4(pos, 1.0)).xyz;
}

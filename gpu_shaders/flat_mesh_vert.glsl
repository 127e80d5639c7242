/* Flat-lit mesh for offscreen checks: world-space position and normal in, clip-space out. */
void main()
{
  gl_Position = shading.view_projection * vec4(pos, 1.0);
  shade = abs(dot(normalize(nor), shading.light_dir.xyz));
}

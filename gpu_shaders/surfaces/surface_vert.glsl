/* Preview: pattern vertex `uv` of instance gl_InstanceID, at its control point plus the surface's point; when lit,
 * the shading normal from central differences in the domain (the surface's own normal, poles included up to the
 * difference step: four more evaluations, skipped for unlit drawing). */
void main()
{
  vec3 p = surface_point(kind, uv, shape);
  vec3 world = control_point(first_instance + gl_InstanceID).xyz + p;
  gl_Position = shading.view_projection * vec4(world, 1.0);
  view_position = (shading.model_view * vec4(world, 1.0)).xyz;
  view_normal = vec3(0.0, 0.0, 1.0);
  if (shading.lit_range.y == 0.0) {
    shade = 1.0;
    return;
  }
  float h = 1.0 / 1024.0;
  vec3 du = surface_point(kind, uv + vec2(h, 0.0), shape) - surface_point(kind, uv - vec2(h, 0.0), shape);
  vec3 dv = surface_point(kind, uv + vec2(0.0, h), shape) - surface_point(kind, uv - vec2(0.0, h), shape);
  vec3 n = cross(du, dv);
  float len = length(n);
  n = len > 1e-20 ? n / len : normalize(p + vec3(0.0, 0.0, 1e-6));
  shade = abs(dot(n, shading.light_dir.xyz));
  view_normal = mat3(shading.normal_matrix) * n;
}

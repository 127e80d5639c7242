/* Solid mode's studio lighting, as Blender's viewport lights its own objects (so that a preview drawn instead of an
 * object looks like the object would): up to four lights of the user's studio light, each with a diffuse colour, a
 * specular colour and a wrap ("smooth") that softens its terminator, plus an ambient colour; a normalised Blinn
 * highlight that blends into a wrapped environment term as the wrap grows, and a Schlick-like rim on the specular
 * colour. Lights and normals are in view space; `I` points from the surface to the eye. Returns linear RGB. */

vec4 wrap_light(vec4 n_dot_l, vec4 w)
{
  vec4 w1 = w + 1.0;
  return clamp((n_dot_l + w) / (w1 * w1), 0.0, 1.0);
}

vec3 solid_light(vec3 base, float roughness, float metallic, vec3 N, vec3 I)
{
  mat4 dirs = mat4(shading.light_direction[0], shading.light_direction[1], shading.light_direction[2],
                   shading.light_direction[3]);
  vec4 wrap = vec4(shading.light_diffuse[0].w, shading.light_diffuse[1].w, shading.light_diffuse[2].w,
                   shading.light_diffuse[3].w);
  vec4 n_dot_l = vec4(dot(dirs[0].xyz, N), dot(dirs[1].xyz, N), dot(dirs[2].xyz, N), dot(dirs[3].xyz, N));
  bool specular_on = shading.ambient.w > 0.5;
  vec3 diffuse_color = specular_on ? base * (1.0 - metallic) : base;
  vec3 specular_color = specular_on ? mix(vec3(0.05), base, metallic) : vec3(0.0);
  vec3 specular = shading.ambient.rgb;
  if (specular_on) {
    vec3 R = -reflect(I, N);
    vec4 cos_h, n_dot_l_clamped, r_dot_l;
    for (int i = 0; i < 4; i++) {
      vec3 L = dirs[i].xyz;
      r_dot_l[i] = dot(L, R);
      cos_h[i] = clamp(dot(normalize(L + I), N), 0.0, 1.0);
      n_dot_l_clamped[i] = clamp(dot(L, N), 0.0, 1.0);
    }
    vec4 gloss = vec4(1.0 - roughness) * (1.0 - wrap);
    vec4 shininess = exp2(10.0 * gloss + 1.0);
    vec4 blinn = pow(cos_h, shininess) * n_dot_l_clamped * (shininess * 0.125 + 1.0);
    vec4 env = wrap_light(r_dot_l, mix(wrap, vec4(1.0), roughness));
    vec4 s = mix(blinn, env, wrap * wrap);
    for (int i = 0; i < 4; i++) {
      specular += s[i] * shading.light_specular[i].rgb;
    }
    float fresnel = exp2(-8.35 * clamp(dot(N, I), 0.0, 1.0)) * (1.0 - roughness);
    specular_color = mix(specular_color, vec3(1.0), fresnel);
  }
  specular *= specular_color;
  vec4 d = wrap_light(n_dot_l, wrap);
  vec3 diffuse = shading.ambient.rgb;
  for (int i = 0; i < 4; i++) {
    diffuse += d[i] * shading.light_diffuse[i].rgb;
  }
  diffuse *= diffuse_color * (1.0 - dot(specular_color, vec3(1.0 / 3.0)));
  return diffuse + specular;
}

/* Solid mode's MatCap lighting: the MatCap looked up by the view-space normal, turned so that the lookup follows the
 * incident direction `I` in perspective views: its diffuse pass (the texture's left half) times the base colour, plus
 * its specular pass (the right half) where the specular highlights are on (ambient.w). */
vec3 matcap_light(vec3 base, vec3 N, vec3 I)
{
  float a = 1.0 / (1.0 + I.z);
  float b = -I.x * I.y * a;
  vec3 b1 = vec3(1.0 - I.x * I.x * a, b, -I.x);
  vec3 b2 = vec3(b, 1.0 - I.y * I.y * a, -I.y);
  vec2 uv = vec2(dot(b1, N), dot(b2, N)) * 0.496 + 0.5;
  vec3 diffuse = textureLod(matcap, vec2(0.5 * uv.x, uv.y), 0.0).rgb;
  vec3 specular = textureLod(matcap, vec2(0.5 + 0.5 * uv.x, uv.y), 0.0).rgb;
  return diffuse * base + specular * shading.ambient.w;
}

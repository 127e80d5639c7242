/* One-point parametric surfaces: the formulas of kernels/surfaces/parametric.py in float32. `kind` is the index
 * of the surface in parametric.SURFACES; `s` its shape parameters in dataclass field order. uv in [0, 1]^2. */

const float PI = 3.141592653589793;
const float TWO_PI = 6.283185307179586;

float signed_pow(float x, float e)
{
  return sign(x) * pow(abs(x), e);
}

/* (cos 2 pi t, sin 2 pi t), exact at quarter turns (kernels parametric.cos_sin_turns). */
vec2 cos_sin_turns(float t)
{
  float q = floor(4.0 * t);
  float r = t - q * 0.25;
  float c = cos(TWO_PI * r);
  float s = sin(TWO_PI * r);
  int k = int(mod(q, 4.0));
  if (k == 1) {
    return vec2(-s, c);
  }
  if (k == 2) {
    return vec2(-c, -s);
  }
  if (k == 3) {
    return vec2(s, -c);
  }
  return vec2(c, s);
}

vec3 surface_point(int kind, vec2 uv, vec4 s)
{
  float u = uv.x;
  float v = uv.y;
  if (kind == 0) { /* sphere: radius; fi = pi u from the +z pole, theta = 2 pi v */
    float fi = PI * u;
    float th = TWO_PI * v;
    return s.x * vec3(sin(fi) * cos(th), sin(fi) * sin(th), cos(fi));
  }
  if (kind == 1) { /* cone: radius, height */
    float th = TWO_PI * u;
    float k = (s.y - v * s.y) / s.y * s.x;
    return vec3(k * cos(th), k * sin(th), v * s.y);
  }
  if (kind == 2) { /* torus: major, minor */
    float a = TWO_PI * u;
    float t = TWO_PI * v;
    float ring = s.x + s.y * cos(t);
    return vec3(ring * cos(a), ring * sin(a), s.y * sin(t));
  }
  if (kind == 3) { /* Steiner's Roman surface as coded: a */
    float uu = PI * u;
    float vv = PI * v;
    float cv = cos(vv);
    return (s.x * s.x) *
           vec3(cv * cv * sin(2.0 * uu) / 2.0, sin(uu) * sin(2.0 * vv) / 2.0, cos(uu) * sin(2.0 * vv) / 2.0);
  }
  if (kind == 4) { /* figure-8 Klein bottle: radius */
    float th = TWO_PI * u;
    float ph = TWO_PI * v;
    float w = s.x + cos(th / 2.0) * sin(ph) - sin(th / 2.0) * sin(2.0 * ph);
    return vec3(w * cos(th), w * sin(th), sin(th / 2.0) * sin(ph) + cos(th / 2.0) * sin(2.0 * ph));
  }
  if (kind == 5) { /* Mobius band: radius, width */
    float t = TWO_PI * u;
    float w = s.y * (v - 0.5);
    float ring = s.x + w * cos(t / 2.0);
    return vec3(ring * cos(t), ring * sin(t), w * sin(t / 2.0));
  }
  if (kind == 6) { /* trefoil-knot tube on its Frenet frame: scale, tube */
    float t = TWO_PI * u;
    float ph = TWO_PI * v;
    vec3 c = vec3(sin(t) + 2.0 * sin(2.0 * t), cos(t) - 2.0 * cos(2.0 * t), -sin(3.0 * t));
    vec3 d1 = vec3(cos(t) + 4.0 * cos(2.0 * t), -sin(t) + 4.0 * sin(2.0 * t), -3.0 * cos(3.0 * t));
    vec3 d2 = vec3(-sin(t) - 8.0 * sin(2.0 * t), -cos(t) + 8.0 * cos(2.0 * t), 9.0 * sin(3.0 * t));
    vec3 T = normalize(d1);
    vec3 B = normalize(cross(d1, d2));
    vec3 N = cross(B, T);
    return s.x * c + s.y * (cos(ph) * N + sin(ph) * B);
  }
  /* superellipsoid: size, e1, e2 */
  vec2 eta = cos_sin_turns(0.25 - 0.5 * u);
  vec2 om = cos_sin_turns(v);
  float ce = signed_pow(eta.x, s.y);
  return s.x * vec3(ce * signed_pow(om.x, s.z), ce * signed_pow(om.y, s.z), signed_pow(eta.y, s.y));
}

vec4 control_point(int i)
{
  return texelFetch(control_points, ivec2(i % tex_width, i / tex_width), 0);
}

/* PN / Phong / linear surface of one input triangle at one refinement-pattern vertex (kernels/patch_instances.py
 * describes the codes and the control texels; kernels/patches.py the surfaces). Needs partition.glsl, the
 * sampler `control` and the push constants `tex_width`, `method` (0 linear, 1 Phong, 2 PN), `pn_quadratic`
 * and `fractional`. Edge points are evaluated along their edge's canonical direction from the two endpoints
 * only, so both triangles of a shared edge compute the same vertex. */

#define CONTROL_ROWS 14

vec4 control_row(int tri, int row)
{
  int i = tri * CONTROL_ROWS + row;
  return texelFetch(control, ivec2(i % tex_width, i / tex_width), 0);
}

vec3 tangent_point(vec3 pi, vec3 pj, vec3 ni)
{
  return (2.0 * pi + pj - dot(pj - pi, ni) * ni) / 3.0;
}

vec3 safe_normalize(vec3 v)
{
  float len = length(v);
  return len > 0.0 ? v / len : vec3(0.0);
}

vec3 reflected_mid_normal(vec3 pi, vec3 pj, vec3 ni, vec3 nj)
{
  vec3 d = pj - pi;
  float dd = dot(d, d);
  float v = dd > 0.0 ? 2.0 * dot(d, ni + nj) / dd : 0.0;
  return safe_normalize(ni + nj - v * d);
}

/* Phong offset of the pair (i, j): p*_1 - p on the mixed term, -(d_ij N_i + d_ji N_j). */
vec3 phong_pair(vec3 pi, vec3 pj, vec3 ni, vec3 nj)
{
  return -(dot(pj - pi, ni) * ni + dot(pi - pj, nj) * nj);
}

vec3 edge_position(vec3 pa, vec3 pb, vec3 na, vec3 nb, float aa, float ab, float t)
{
  float s = 1.0 - t;
  if (method == 2) {
    vec3 b1 = tangent_point(pa, pb, na), b2 = tangent_point(pb, pa, nb);
    return s * s * s * pa + 3.0 * s * s * t * b1 + 3.0 * s * t * t * b2 + t * t * t * pb;
  }
  vec3 p = s * pa + t * pb;
  if (method == 1) {
    p += (s * aa + t * ab) * (s * t) * phong_pair(pa, pb, na, nb);
  }
  return p;
}

/* Corners as separate parameters, not arrays (Blender's Metal translation does not rewrite array parameters). */
vec3 face_position(vec3 p0, vec3 p1, vec3 p2, vec3 n0, vec3 n1, vec3 n2, vec3 a, vec3 b)
{
  if (method == 2) {
    vec3 b210 = tangent_point(p0, p1, n0), b120 = tangent_point(p1, p0, n1);
    vec3 b021 = tangent_point(p1, p2, n1), b012 = tangent_point(p2, p1, n2);
    vec3 b102 = tangent_point(p2, p0, n2), b201 = tangent_point(p0, p2, n0);
    vec3 e = (b210 + b120 + b021 + b012 + b102 + b201) / 6.0;
    vec3 b111 = e + (e - (p0 + p1 + p2) / 3.0) / 2.0;
    return b.x * b.x * b.x * p0 + b.y * b.y * b.y * p1 + b.z * b.z * b.z * p2 +
           3.0 * b.x * b.x * b.y * b210 + 3.0 * b.x * b.y * b.y * b120 + 3.0 * b.y * b.y * b.z * b021 +
           3.0 * b.y * b.z * b.z * b012 + 3.0 * b.x * b.z * b.z * b102 + 3.0 * b.x * b.x * b.z * b201 +
           6.0 * b.x * b.y * b.z * b111;
  }
  vec3 q = b.x * p0 + b.y * p1 + b.z * p2;
  if (method == 1) {
    float alpha = b.x * a.x + b.y * a.y + b.z * a.z;
    q += alpha * (b.x * b.y * phong_pair(p0, p1, n0, n1) + b.y * b.z * phong_pair(p1, p2, n1, n2) +
                  b.z * b.x * phong_pair(p2, p0, n2, n0));
  }
  return q;
}

/* The normal field (PN quadratic, or linear) at barycentrics b from corner normals s: unit. */
vec3 face_normal(vec3 p0, vec3 p1, vec3 p2, vec3 s0, vec3 s1, vec3 s2, vec3 b)
{
  if (method == 2 && pn_quadratic != 0) {
    return safe_normalize(b.x * b.x * s0 + b.y * b.y * s1 + b.z * b.z * s2 +
                          b.x * b.y * reflected_mid_normal(p0, p1, s0, s1) +
                          b.y * b.z * reflected_mid_normal(p1, p2, s1, s2) +
                          b.z * b.x * reflected_mid_normal(p2, p0, s2, s0));
  }
  return safe_normalize(b.x * s0 + b.y * s1 + b.z * s2);
}

/* Evaluate pattern vertex `code` of triangle `tri` with its levels `lev` (f0, f1, f2, f_inner) and segment
 * counts `counts` (n0, n1, n2, m). Normals from the shading normals (`shading_normals`, split corners kept)
 * or the one-per-vertex geometry normals. */
void evaluate(int tri, vec4 code, vec4 lev, vec4 counts, bool shading_normals, out vec3 pos, out vec3 nor,
              out vec3 b)
{
  vec3 p[3], n[3], s[3];
  float a[3], flip[3];
  for (int i = 0; i < 3; i++) {
    vec4 r = control_row(tri, i);
    p[i] = r.xyz;
    a[i] = r.w;
    vec4 g = control_row(tri, 3 + i);
    n[i] = g.xyz;
    flip[i] = g.w;
    s[i] = shading_normals ? control_row(tri, 6 + i).xyz : n[i];
  }
  bool frac = fractional != 0;
  int kind = int(code.x);
  b = vec3(0.0);
  if (kind == 0) {
    int c = int(code.y);
    b[c] = 1.0;
    pos = p[c];
  }
  else if (kind == 1) {
    int e = int(code.y), f = (e + 1) % 3;
    float nseg = counts[e];
    bool flipped = flip[e] > 0.5;
    float t = param(lev[e], nseg, flipped ? nseg - code.z : code.z, frac);
    int lo = flipped ? f : e, hi = flipped ? e : f;
    pos = edge_position(p[lo], p[hi], n[lo], n[hi], a[lo], a[hi], t);
    float tl = flipped ? 1.0 - t : t;
    b[e] = 1.0 - tl;
    b[f] = tl;
  }
  else {
    float m = counts.w, k = code.y, j = code.w;
    int c = int(code.z);
    float side = m - 2.0 * k;
    if (side == 0.0) {
      b = vec3(1.0 / 3.0);
    }
    else {
      float p_ring = param(lev.w, m, k, frac), p_point = param(lev.w, m, k + j, frac);
      float off = (2.0 / 3.0) * p_ring;
      float span = 1.0 - 2.0 * p_ring;
      float phi = span > 0.0 ? (p_point - p_ring) / span : j / side;
      float b_next = off + phi * (1.0 - 3.0 * off);
      b[c] = 1.0 - b_next - off;
      b[(c + 1) % 3] = b_next;
      b[(c + 2) % 3] = off;
    }
    pos = face_position(p[0], p[1], p[2], n[0], n[1], n[2], vec3(a[0], a[1], a[2]), b);
  }
  nor = face_normal(p[0], p[1], p[2], s[0], s[1], s[2], b);
}

/* Corner UVs of `tri` interpolated at barycentric `b`. */
vec2 uv_at(int tri, vec3 b)
{
  vec4 uv01 = control_row(tri, 9);
  return b.x * uv01.xy + b.y * uv01.zw + b.z * control_row(tri, 10).xy;
}

/* Corner tangents (xyz) and bitangent signs (w) of `tri` interpolated at barycentric `b`. */
vec4 tangent_at(int tri, vec3 b)
{
  return b.x * control_row(tri, 11) + b.y * control_row(tri, 12) + b.z * control_row(tri, 13);
}

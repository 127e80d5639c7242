// Tube body for one run of tubes with `n` sides, one work item per point (the numpy reference is
// kernels.tubes._write_body: same vertex, edge, face and corner numbering).
// centre, nrm, bin: (P, 3) float; radius: (P) float; seg: (P) int segment id or -1; nxt: (P) int next point;
// u0, u1: (P) float UV u at the segment's ends (read when write_uv); normals written only when write_normals, face
// materials only when write_material; ring: (n, 2) float cos, sin of the sides' angles (the numpy reference's float32
// table, so both paths place vertices alike). Outputs are whole-mesh arrays written at offsets v0 (vertices), e0
// (edges), f0 (faces), c0 (corners); face_offsets gets every quad's first corner; n_pts points and n_seg segments.
__kernel void tube_body(__global const float *centre, __global const float *nrm, __global const float *bin,
                        __global const float *radius, __global const int *seg, __global const int *nxt,
                        __global const float *u0, __global const float *u1, __global const int *material,
                        __global const float2 *ring,
                        const int n, const int n_pts, const int n_seg, const long v0, const long e0,
                        const long f0, const long c0, const int write_uv, const int write_normals,
                        const int write_material,
                        __global float *positions, __global float *normals, __global int *edges,
                        __global int *corner_verts, __global int *corner_edges, __global int *face_offsets,
                        __global int *face_material, __global float *uvs)
{
  const int p = get_global_id(0);
  if (p >= n_pts) {
    return;
  }
  const float3 c = vload3(p, centre), N = vload3(p, nrm), B = vload3(p, bin);
  const float r = radius[p];
  const long vp = v0 + (long)p * n;
  for (int j = 0; j < n; ++j) {
    const float2 cs = ring[j];
    const float3 radial = cs.x * N + cs.y * B;
    if (write_normals) {
      vstore3(radial, vp + j, normals);
    }
    vstore3(c + r * radial, vp + j, positions);
    const long er = e0 + (long)p * n + j;
    edges[2 * er] = (int)(vp + j);
    edges[2 * er + 1] = (int)(vp + (j + 1) % n);
  }
  const int s = seg[p];
  if (s < 0) {
    return;
  }
  const long vq = v0 + (long)nxt[p] * n;
  const long ring_p = e0 + (long)p * n, ring_q = e0 + (long)nxt[p] * n;
  const long along = e0 + ((long)n_pts + s) * n;
  for (int j = 0; j < n; ++j) {
    const int j1 = (j + 1) % n;
    const long f = f0 + (long)s * n + j;
    const long k = c0 + 4 * ((long)s * n + j);
    edges[2 * (along + j)] = (int)(vp + j);
    edges[2 * (along + j) + 1] = (int)(vq + j);
    corner_verts[k] = (int)(vp + j);
    corner_verts[k + 1] = (int)(vp + j1);
    corner_verts[k + 2] = (int)(vq + j1);
    corner_verts[k + 3] = (int)(vq + j);
    corner_edges[k] = (int)(ring_p + j);
    corner_edges[k + 1] = (int)(along + j1);
    corner_edges[k + 2] = (int)(ring_q + j);
    corner_edges[k + 3] = (int)(along + j);
    face_offsets[f] = (int)k;
    if (write_material) {
      face_material[f] = material[p];
    }
    if (write_uv) {
      const float va = (float)j / n, vb = (float)(j + 1) / n;
      uvs[2 * k] = u0[p];     uvs[2 * k + 1] = va;
      uvs[2 * k + 2] = u0[p]; uvs[2 * k + 3] = vb;
      uvs[2 * k + 4] = u1[p]; uvs[2 * k + 5] = vb;
      uvs[2 * k + 6] = u1[p]; uvs[2 * k + 7] = va;
    }
  }
}

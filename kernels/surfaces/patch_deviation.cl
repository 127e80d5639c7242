// How far triangles stray from rational Bézier patches, measured at barycentric sample points against the surface at
// the same point of their corners' (u, v). kernels/surfaces/patch_deviation_opencl.py launches these; the numpy
// references are `bezier_patches.grid_deviation` (cells of an inner grid) and `bezier_patches._deviation` (triangles
// given one by one). Double precision throughout, as the references.
//
// The nets are K x K homogeneous points (w x, w y, w z, w), degree K - 1 both ways: K is 4 (bicubic) unless the build
// defines it (-DK=<k>, k from 2 to 7: patch_deviation_opencl._options). The warm-up builds each of them:
// build variants: -DK=2 | -DK=3 | -DK=5 | -DK=6 | -DK=7

#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#pragma OPENCL FP_CONTRACT OFF

#ifndef K
#define K 4
#endif
#define DEGREE (K - 1)

// Bernstein basis of degree K - 1 at t, by products of powers (as rational_bezier.bernstein).
static void basis(double t, double *b) {
    double tp[K], sp[K];
    double s = 1.0 - t;
    tp[0] = sp[0] = 1.0;
    for (int i = 1; i < K; ++i) {
        tp[i] = tp[i - 1] * t;
        sp[i] = sp[i - 1] * s;
    }
    double c = 1.0;  // binomial coefficient C(K - 1, i)
    for (int i = 0; i < K; ++i) {
        b[i] = c * tp[i] * sp[DEGREE - i];
        c = c * (double)(DEGREE - i) / (double)(i + 1);
    }
}

// The Cartesian point of net h (K x K x 4, i along u, j along v) at (u, v).
static double3 point_at(__global const double *h, double u, double v) {
    double bu[K], bv[K];
    basis(u, bu);
    basis(v, bv);
    double4 s = (double4)(0.0);
    for (int i = 0; i < K; ++i) {
        double4 row = (double4)(0.0);
        for (int j = 0; j < K; ++j) row += bv[j] * vload4((size_t)(i * K + j), h);
        s += bu[i] * row;
    }
    return s.xyz / s.w;
}

// The Cartesian point of u basis values b (K,) and a net already contracted along v (K homogeneous points).
static double3 at_sixths(const double *b, const double4 *along_v) {
    double4 s = (double4)(0.0);
    for (int i = 0; i < K; ++i) s += b[i] * along_v[i];
    return s.xyz / s.w;
}

// One work-item a cell of a patch's inner grid: the cell between inner points c and c + 1 along u (c from 1) and
// along v, cut along its (c, c')-(c + 1, c' + 1) diagonal. cell_start (P + 1,): the first cell of each patch;
// width (P,): its cells a row (inner steps along u - 2); t_start (P, 2): where its parameters along u and along v
// start in t. samples: for each of n_samples, the triangle (0: (0,0) (1,0) (1,1); 1: (0,0) (1,1) (0,1)), its offsets in
// the cell in sixths along u and v, and which side it lies on (0 inside, 1 a side along u, 2 along v); weights: its
// barycentric weights of the triangle's second and third corners. out (cells, 3): the largest distance anywhere, on
// the sides along u, on the sides along v.
__kernel void grid_cells(__global const double *nets, __global const int *patch_of_net, __global const long *cell_start,
                         __global const int *width, __global const long *t_start, __global const double *t,
                         __global const int *samples, __global const double *weights, const int n_samples,
                         const int n_patches, const long n_cells, __global double *out) {
    long g = get_global_id(0);
    if (g >= n_cells) return;
    int lo = 0, hi = n_patches - 1;  // the patch whose cells hold g
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (cell_start[mid] <= g) lo = mid; else hi = mid - 1;
    }
    int p = lo;
    long own = g - cell_start[p];
    int cu = (int)(own % width[p]) + 1, cv = (int)(own / width[p]) + 1;
    __global const double *h = nets + (size_t)patch_of_net[p] * K * K * 4;
    __global const double *tu = t + t_start[2 * p], *tv = t + t_start[2 * p + 1];
    // the v basis at the cell's seven sixths contracted with the net once each, then each point a dot product
    double bu[7][K], bv[K];
    double4 along_v[7][K];
    double u0 = tu[cu], du = tu[cu + 1] - u0, v0 = tv[cv], dv = tv[cv + 1] - v0;
    for (int a = 0; a < 7; ++a) {
        basis(u0 + (double)a / 6.0 * du, bu[a]);
        basis(v0 + (double)a / 6.0 * dv, bv);
        for (int i = 0; i < K; ++i) {
            double4 row = (double4)(0.0);
            for (int j = 0; j < K; ++j) row += bv[j] * vload4((size_t)(i * K + j), h);
            along_v[a][i] = row;
        }
    }
    double3 corner[4];  // (0,0) (1,0) (1,1) (0,1)
    corner[0] = at_sixths(bu[0], along_v[0]);
    corner[1] = at_sixths(bu[6], along_v[0]);
    corner[2] = at_sixths(bu[6], along_v[6]);
    corner[3] = at_sixths(bu[0], along_v[6]);
    double worst[3] = {0.0, 0.0, 0.0};
    for (int s = 0; s < n_samples; ++s) {
        int tri = samples[4 * s], iu = samples[4 * s + 1], iv = samples[4 * s + 2], side = samples[4 * s + 3];
        double3 c0 = corner[0], c1 = corner[tri == 0 ? 1 : 2], c2 = corner[tri == 0 ? 2 : 3];
        double3 on_mesh = c0 + weights[2 * s] * (c1 - c0) + weights[2 * s + 1] * (c2 - c0);
        double3 gap = at_sixths(bu[iu], along_v[iv]) - on_mesh;
        double d = sqrt(gap.x * gap.x + gap.y * gap.y + gap.z * gap.z);
        worst[0] = fmax(worst[0], d);
        if (side) worst[side] = fmax(worst[side], d);
    }
    out[3 * g] = worst[0];
    out[3 * g + 1] = worst[1];
    out[3 * g + 2] = worst[2];
}

// One work-item a triangle: corners (T, 3, 3), their (u, v) (T, 3, 2) and patch (T,); bary (n_points, 3). out (T,):
// the largest distance at those barycentric points between the triangle and its patch at the same point of its
// corners' (u, v).
__kernel void triangles(__global const double *nets, __global const double *corners, __global const double *uv,
                        __global const long *patch, __global const double *bary, const int n_points, const long n,
                        __global double *out) {
    long g = get_global_id(0);
    if (g >= n) return;
    __global const double *h = nets + (size_t)patch[g] * K * K * 4;
    double3 c0 = vload3(3 * g, corners), c1 = vload3(3 * g + 1, corners), c2 = vload3(3 * g + 2, corners);
    double2 t0 = vload2(3 * g, uv), t1 = vload2(3 * g + 1, uv), t2 = vload2(3 * g + 2, uv);
    double worst = 0.0;
    for (int s = 0; s < n_points; ++s) {
        double b0 = bary[3 * s], b1 = bary[3 * s + 1], b2 = bary[3 * s + 2];
        double3 on_mesh = b0 * c0 + b1 * c1 + b2 * c2;
        double2 at = b0 * t0 + b1 * t1 + b2 * t2;
        double3 gap = point_at(h, at.x, at.y) - on_mesh;
        worst = fmax(worst, sqrt(gap.x * gap.x + gap.y * gap.y + gap.z * gap.z));
    }
    out[g] = worst;
}

// One work-item a point: (u, v) (N, 2) of patch (N,) -> out (N, 3), the surface there.
__kernel void points(__global const double *nets, __global const double *uv, __global const long *patch, const long n,
                     __global double *out) {
    long g = get_global_id(0);
    if (g >= n) return;
    double2 at = vload2(g, uv);
    vstore3(point_at(nets + (size_t)patch[g] * K * K * 4, at.x, at.y), g, out);
}

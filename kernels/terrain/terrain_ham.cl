// Height acceleration map ([Nunes 2011, §5.6.1]) and the per-tile table (§5.6.2). Same operation order as the
// numpy reference in terrain/analysis.py: M = |Sobel(H)|, HAM = |Sobel(M)|, clamp-to-edge borders. Contraction is
// off (a + 2b would become one fma, and gx * gx + gy * gy another), so the device gives the reference's bits.
#pragma OPENCL FP_CONTRACT OFF

inline float at(__global const float *a, int x, int y, int w, int h) {
    x = clamp(x, 0, w - 1);
    y = clamp(y, 0, h - 1);
    return a[(long)y * w + x];
}

// dst = |Sobel(src * scale)|; one work item per sample.
__kernel void sobel_mag(__global const float *src, __global float *dst, int w, int h, float scale) {
    int x = get_global_id(0), y = get_global_id(1);
    if (x >= w || y >= h) return;
    float a00 = at(src, x - 1, y - 1, w, h) * scale, a10 = at(src, x, y - 1, w, h) * scale;
    float a20 = at(src, x + 1, y - 1, w, h) * scale, a01 = at(src, x - 1, y, w, h) * scale;
    float a21 = at(src, x + 1, y, w, h) * scale, a02 = at(src, x - 1, y + 1, w, h) * scale;
    float a12 = at(src, x, y + 1, w, h) * scale, a22 = at(src, x + 1, y + 1, w, h) * scale;
    float top = a00 + 2.0f * a10 + a20, bottom = a02 + 2.0f * a12 + a22;
    float left = a00 + 2.0f * a01 + a02, right = a20 + 2.0f * a21 + a22;
    float gx = bottom - top, gy = right - left;
    dst[(long)y * w + x] = sqrt(gx * gx + gy * gy);
}

// One work item per tile: HAM max, height min/max and the first highest sample in row-major order.
__kernel void tile_stats(__global const float *ham, __global const float *hgt, int w, int h, int ts, int ntx,
                         int nty, __global float *ham_max, __global float *h_min, __global float *h_max,
                         __global int *peak_x, __global int *peak_y) {
    int tx = get_global_id(0), ty = get_global_id(1);
    if (tx >= ntx || ty >= nty) return;
    int x0 = tx * ts, y0 = ty * ts, x1 = min(x0 + ts, w - 1), y1 = min(y0 + ts, h - 1);
    float hm = -INFINITY, lo = INFINITY, hi = -INFINITY;
    int px = x0, py = y0;
    for (int y = y0; y <= y1; ++y) {
        for (int x = x0; x <= x1; ++x) {
            long i = (long)y * w + x;
            hm = fmax(hm, ham[i]);
            float v = hgt[i];
            lo = fmin(lo, v);
            if (v > hi) { hi = v; px = x; py = y; }
        }
    }
    int t = ty * ntx + tx;
    ham_max[t] = hm; h_min[t] = lo; h_max[t] = hi; peak_x[t] = px; peak_y[t] = py;
}

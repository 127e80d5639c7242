// Loop subdivision as [Concheiro et al.] runs it: one invocation per coarse triangle, from its packed 1-ring alone, no
// communication between invocations (kernels/subdivision/loop_stencils.py builds the tables; its `apply` is the
// numpy reference). Every invocation writes all vertices of its own sub-triangles; a vertex shared with a
// neighbour gets the same bits from both (same weights, same order), so the writes agree.

#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#pragma OPENCL FP_CONTRACT OFF

__kernel void apply_stencils(__global const long *patch, __global const long *outputs, __global const long *stencil,
                             __global const double *weights, __global const double *src, __global double *dst,
                             const int n_faces, const int width_p, const int rows, const int width) {
    int f = get_global_id(0);
    if (f >= n_faces) return;
    __global const long *p = patch + (size_t)f * width_p;
    __global const double *w = weights + (size_t)stencil[f] * rows * width_p;
    for (int k = 0; k < rows; ++k) {
        long out = outputs[(size_t)f * rows + k];
        for (int j = 0; j < width; ++j) {
            double sum = 0.0;
            for (int i = 0; i < width_p && p[i] >= 0; ++i) sum += w[k * width_p + i] * src[p[i] * width + j];
            dst[out * width + j] = sum;
        }
    }
}

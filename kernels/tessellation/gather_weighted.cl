// Weighted gather: out[r, c] = sum_q w[r, q] * values[idx[r, q], c]
// values: (K, channels) float32; idx: (n, taps) int32; w: (n, taps) float32; out: (n, channels) float32.
// One work item per output row; the numpy reference is kernels.interpolate.gather_weighted_numpy.
// No contraction into fused multiply-adds: every product is rounded, so rows whose weights are a permutation of
// each other over the same values (the two faces of an edge) sum to the same bits.
#pragma OPENCL FP_CONTRACT OFF

__kernel void gather_weighted(__global const float *values, const int channels,
                              __global const int *idx, __global const float *w, const int taps,
                              __global float *out, const int n)
{
    const int row = get_global_id(0);
    if (row >= n) {
        return;
    }
    for (int c = 0; c < channels; ++c) {
        float acc = 0.0f;
        for (int q = 0; q < taps; ++q) {
            acc += w[row * taps + q] * values[(long)idx[row * taps + q] * channels + c];
        }
        out[(long)row * channels + c] = acc;
    }
}

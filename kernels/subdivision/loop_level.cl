// One level of Loop subdivision on an OpenCL device: the numpy reference is kernels/subdivision/loop.py with
// loop_topology.py. Same factored rules (linear midpoint -> averaging -> correction factor cf(n)), same numbering
// (vertices V + e, faces 4 f + slot in T/L/C/R order, edges 2 e, 2 e + 1 and 2 E + 3 f + k), for meshes whose
// creases and corners are all infinitely sharp (boundaries included); semi-sharp creases stay on numpy.
//
// Per level: edge_faces (F) fills the faces beside each edge; odd_vertices (E) and even_vertices (V) write the
// new values; refine_faces (F), refine_edges (E) and refine_incidence (V + E) build the next level. Each
// vertex's incident edges are a fixed list (offsets, incident), so every sum has one order.

#pragma OPENCL EXTENSION cl_khr_fp64 : enable

// ---- faces beside each edge --------------------------------------------------------------------------------

__kernel void edge_faces(__global const int *face_edges, __global const uchar *side, __global int *edge_face,
                         __global int *edge_local, const int n_faces) {
    int f = get_global_id(0);
    if (f >= n_faces) return;
    for (int k = 0; k < 3; ++k) {
        int e = face_edges[3 * f + k];
        int s = side[3 * f + k];
        edge_face[2 * e + s] = f;
        edge_local[2 * e + s] = k;
    }
}

// ---- new values ------------------------------------------------------------------------------------------------

__kernel void odd_vertices(__global const int *tris, __global const int *edges, __global const int *edge_face,
                           __global const int *edge_local, __global const uchar *sharp, __global const double *src,
                           __global double *dst, const int n_edges, const int n_vertices, const int width,
                           const double cf6) {
    int e = get_global_id(0);
    if (e >= n_edges) return;
    int a = edges[2 * e], b = edges[2 * e + 1];
    int f1 = edge_face[2 * e + 1];
    __global double *out = dst + (size_t)(n_vertices + e) * width;
    if (sharp[e] || f1 < 0) {  // crease or boundary: the midpoint
        for (int j = 0; j < width; ++j) out[j] = 0.5 * (src[(size_t)a * width + j] + src[(size_t)b * width + j]);
        return;
    }
    int f0 = edge_face[2 * e];
    int c = tris[3 * f0 + (edge_local[2 * e] + 2) % 3];
    int d = tris[3 * f1 + (edge_local[2 * e + 1] + 2) % 3];
    if (d < c) { int t = c; c = d; d = t; }  // by id, as the reference sums them
    for (int j = 0; j < width; ++j) {
        double pa = src[(size_t)a * width + j], pb = src[(size_t)b * width + j];
        double pc = src[(size_t)c * width + j], pd = src[(size_t)d * width + j];
        double m = 0.5 * (pa + pb);
        double ring = pa + pb;
        ring += 0.5 * (pa + pc) + 0.5 * (pb + pc);
        ring += 0.5 * (pa + pd) + 0.5 * (pb + pd);
        out[j] = m + cf6 * ((0.25 * m + (0.75 / 6.0) * ring) - m);
    }
}

__kernel void even_vertices(__global const int *edges, __global const int *offsets, __global const int *incident,
                            __global const uchar *sharp, __global const uchar *corner, __global const double *cf,
                            __global const double *src, __global double *dst, const int n_vertices,
                            const int width) {
    int v = get_global_id(0);
    if (v >= n_vertices) return;
    int lo = offsets[v], hi = offsets[v + 1];
    int n = 0, n_sharp = 0;
    for (int i = lo; i < hi; ++i) {
        int e = incident[i];
        if (e < 0) continue;
        n += 1;
        n_sharp += sharp[e];
    }
    __global const double *p = src + (size_t)v * width;
    __global double *out = dst + (size_t)v * width;
    if (n == 0 || corner[v] || n_sharp > 2) {  // corner rule (and loose vertices)
        for (int j = 0; j < width; ++j) out[j] = p[j];
        return;
    }
    bool crease = n_sharp == 2;
    for (int j = 0; j < width; ++j) {
        double sum = 0.0;
        for (int i = lo; i < hi; ++i) {
            int e = incident[i];
            if (e < 0 || (crease && !sharp[e])) continue;
            sum += 0.5 * (src[(size_t)edges[2 * e] * width + j] + src[(size_t)edges[2 * e + 1] * width + j]);
        }
        if (crease) {
            out[j] = 0.5 * p[j] + 0.25 * sum;
        } else {
            double averaged = 0.25 * p[j] + (0.75 / n) * sum;
            out[j] = p[j] + cf[n] * (averaged - p[j]);
        }
    }
}

// ---- the next level's topology -------------------------------------------------------------------------------

__constant int TRI_PATTERN[12] = {0, 3, 5, 3, 1, 4, 3, 4, 5, 5, 4, 2};
__constant int EDGE_PATTERN[12] = {0, 8, 5, 3, 1, 6, 6, 7, 8, 7, 4, 2};
__constant int HALF_OF[12] = {0, -1, 2, 0, 1, -1, -1, -1, -1, -1, 1, 2};

__kernel void refine_faces(__global const int *tris, __global const int *face_edges, __global const uchar *flip,
                           __global const uchar *side, __global int *child_tris, __global int *child_face_edges,
                           __global uchar *child_flip, __global uchar *child_side, __global int *child_edges,
                           __global uchar *child_sharp, const int n_faces, const int n_vertices, const int n_edges,
                           const int with_adjacency) {
    int f = get_global_id(0);
    if (f >= n_faces) return;
    int six[6], nine[9];
    for (int k = 0; k < 3; ++k) {
        int e = face_edges[3 * f + k];
        six[k] = tris[3 * f + k];
        six[3 + k] = n_vertices + e;
        nine[k] = 2 * e + flip[3 * f + k];
        nine[3 + k] = 2 * e + 1 - flip[3 * f + k];
        nine[6 + k] = 2 * n_edges + 3 * f + k;
    }
    for (int i = 0; i < 12; ++i) {
        child_tris[12 * f + i] = six[TRI_PATTERN[i]];
        child_face_edges[12 * f + i] = nine[EDGE_PATTERN[i]];
    }
    for (int k = 0; k < 3; ++k) {
        int e = 2 * n_edges + 3 * f + k;
        child_edges[2 * e] = six[3 + k];
        child_edges[2 * e + 1] = six[3 + (k + 1) % 3];
    }
    if (!with_adjacency) return;
    for (int k = 0; k < 3; ++k) child_sharp[2 * n_edges + 3 * f + k] = 0;
    for (int i = 0; i < 12; ++i) {
        int slot = i / 3, h = HALF_OF[i];
        child_flip[12 * f + i] = h >= 0 ? flip[3 * f + h] : (uchar)(slot != 2);
        child_side[12 * f + i] = h >= 0 ? side[3 * f + h] : (uchar)(slot != 2);
    }
}

__kernel void refine_edges(__global const int *edges, __global const uchar *sharp, __global int *child_edges,
                           __global uchar *child_sharp, const int n_edges, const int n_vertices,
                           const int with_adjacency) {
    int e = get_global_id(0);
    if (e >= n_edges) return;
    int mid = n_vertices + e;
    child_edges[4 * e] = edges[2 * e];
    child_edges[4 * e + 1] = mid;
    child_edges[4 * e + 2] = mid;
    child_edges[4 * e + 3] = edges[2 * e + 1];
    if (with_adjacency) child_sharp[2 * e] = child_sharp[2 * e + 1] = sharp[e];
}

// Incident edges on the next level: an old vertex's edges are the halves at its end of its old edges (same
// offsets); edge vertex V + e has 6 slots: its two halves, then the two inner edges at it in each face beside e
// (-1 where e has one face).
__kernel void refine_incidence(__global const int *edges, __global const int *offsets, __global const int *incident,
                               __global const int *edge_face, __global const int *edge_local,
                               __global int *child_incident, const int n_vertices, const int n_edges) {
    int i = get_global_id(0);
    if (i < n_vertices) {
        for (int j = offsets[i]; j < offsets[i + 1]; ++j) {
            int e = incident[j];
            child_incident[j] = e < 0 ? -1 : 2 * e + (edges[2 * e] != i);
        }
        return;
    }
    int e = i - n_vertices;
    if (e >= n_edges) return;
    __global int *out = child_incident + offsets[n_vertices] + 6 * e;
    out[0] = 2 * e;
    out[1] = 2 * e + 1;
    for (int s = 0; s < 2; ++s) {
        int f = edge_face[2 * e + s], k = edge_local[2 * e + s];
        out[2 + 2 * s] = f < 0 ? -1 : 2 * n_edges + 3 * f + k;
        out[3 + 2 * s] = f < 0 ? -1 : 2 * n_edges + 3 * f + (k + 2) % 3;
    }
}

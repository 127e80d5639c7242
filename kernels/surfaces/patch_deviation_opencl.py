"""How far Tessellate Surface's triangles stray from their patches, measured on an OpenCL device
(``patch_deviation.cl``): the same sample points, the same parameters and double precision as the numpy references
`bezier_patches.grid_deviation` (the cells of each patch's inner grid) and `bezier_patches.deviation._deviation`
(triangles given one by one), which the tests compare them with.

One work-item a cell or a triangle: the patch's net, its corners and every sample point are evaluated in it (no
arrays of sample points are made on the host). Taken on a device with double precision (`supports`).
"""

import numpy as np

PROGRAM = "surfaces/patch_deviation"
#: Work-items a group (the runtime chooses where None).
LOCAL = None
#: Cells or triangles a launch at most: the output of one launch (3 doubles a cell) stays small.
CHUNK = 1 << 20


def supports(runtime):
    """Whether ``runtime`` can measure (double precision)."""
    return runtime is not None and "cl_khr_fp64" in runtime.device.extensions


def _options(k):
    """Build options for nets of k x k points: none for bicubic nets (the program as the warm-up builds it)."""
    return () if int(k) == 4 else (f"-DK={int(k)}",)


def build(runtime, k):
    """Build the program for nets of k x k points now (raises `TesseraError` with the compiler's log)."""
    runtime.program(PROGRAM, _options(k))


def _upload(runtime, array, dtype):
    a = np.ascontiguousarray(array, dtype)
    mf = runtime.cl.mem_flags
    return runtime.buffer(mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=a if a.size else np.zeros(1, dtype))


def _samples(points):
    """The sample table of barycentric ``points`` (S, 3) in each of a cell's two triangles: (2 S, 4) int32 rows
    (triangle, sixths along u, sixths along v, side: 0 inside, 1 on a side along u, 2 along v), and (2 S, 2)
    float64 weights of each triangle's second and third corners — the order and classes of `grid_deviation`."""
    tri_offsets = (np.array([[0, 0], [1, 0], [1, 1]], np.float64), np.array([[0, 0], [1, 1], [0, 1]], np.float64))
    rows, weights = [], []
    for tri, offs in enumerate(tri_offsets):
        for bary in np.asarray(points, np.float64):
            a = bary @ offs
            side = 1 if a[1] in (0.0, 1.0) else 2 if a[0] in (0.0, 1.0) else 0
            rows.append((tri, round(float(a[0]) * 6), round(float(a[1]) * 6), side))
            weights.append((bary[1], bary[2]))
    return np.array(rows, np.int32), np.array(weights, np.float64)


def grid_deviation(runtime, h, n_in, tu, tv, points):
    """The largest distance between each patch's inner-grid triangles and the surface, as
    `bezier_patches.grid_deviation` measures it: nets h (P, k, k, 4) float64; steps n_in (P, 2) int, each at least
    3; parameters tu (P, >= max n_u + 1) and tv (P, >= max n_v + 1), each row from 0 to 1 in its own count of steps;
    barycentric sample points (S, 3). Returns (P, 3) float64: anywhere, on the cells' sides along u, along v."""
    cl, queue = runtime.cl, runtime.queue
    n_in = np.asarray(n_in, np.int64)
    p = len(h)
    out = np.zeros((p, 3))
    if p == 0:
        return out
    width = n_in[:, 0] - 2
    cells = width * (n_in[:, 1] - 2)
    start = np.concatenate([[0], np.cumsum(cells)])
    tu, tv = np.ascontiguousarray(tu, np.float64), np.ascontiguousarray(tv, np.float64)
    t = np.concatenate([tu.ravel(), tv.ravel()])
    t_start = np.stack([np.arange(p) * tu.shape[1], tu.size + np.arange(p) * tv.shape[1]], axis=1)
    samples, weights = _samples(points)
    kernel = runtime.kernel(PROGRAM, "grid_cells", _options(h.shape[1]))
    nets, params = _upload(runtime, h, np.float64), _upload(runtime, t, np.float64)
    sample_buf, weight_buf = _upload(runtime, samples, np.int32), _upload(runtime, weights, np.float64)
    first = 0
    while first < p:  # launches of at most CHUNK cells, whole patches each (a larger patch alone)
        last = min(p, max(first + 1, int(np.searchsorted(start, start[first] + CHUNK, side="right")) - 1))
        n_cells = int(start[last] - start[first])
        if n_cells:
            res = runtime.buffer(cl.mem_flags.WRITE_ONLY, n_cells * 3 * 8)
            kernel(queue, (n_cells,), LOCAL, nets, _upload(runtime, np.arange(first, last), np.int32),
                   _upload(runtime, start[first:last + 1] - start[first], np.int64),
                   _upload(runtime, width[first:last], np.int32), _upload(runtime, t_start[first:last], np.int64),
                   params, sample_buf, weight_buf, np.int32(len(samples)), np.int32(last - first), np.int64(n_cells),
                   res)
            per_cell = np.empty((n_cells, 3))
            cl.enqueue_copy(queue, per_cell, res)
            has = cells[first:last] > 0
            out[np.arange(first, last)[has]] = np.maximum.reduceat(per_cell, (start[first:last] - start[first])[has],
                                                                    axis=0)
        first = last
    queue.finish()
    return out


def triangle_deviation(runtime, h, corners, uv, patch, points):
    """The largest distance of each triangle from its patch at barycentric ``points`` (S, 3), as
    `bezier_patches.deviation._deviation` measures it: nets h (P, k, k, 4) float64, corners (T, 3, 3), their (u, v)
    (T, 3, 2), patch (T,) -> (T,) float64."""
    return _per_item(runtime, "triangles", h, np.empty(len(corners)),
                     [(corners, np.float64), (uv, np.float64), (patch, np.int64)],
                     (_upload(runtime, points, np.float64), np.int32(len(points))))


def points(runtime, h, uv, patch):
    """Points of the surface, as `bezier_patches.evaluate` gives them: nets h (P, k, k, 4) float64, (u, v)
    (N, 2) on patches patch (N,) -> (N, 3) float64."""
    return _per_item(runtime, "points", h, np.empty((len(uv), 3)), [(uv, np.float64), (patch, np.int64)])


def _per_item(runtime, name, h, out, items, extra=()):
    """Kernel ``name`` launched with one work-item an item, at most CHUNK items a launch: its arguments the nets
    h, each of ``items`` ((array (N, ...), dtype)) sliced to the launch's items, ``extra`` (buffers and scalars
    shared by all), the count, and the result, copied into out (N, ...) float64."""
    cl, queue = runtime.cl, runtime.queue
    if len(out) == 0:
        return out
    kernel = runtime.kernel(PROGRAM, name, _options(h.shape[1]))
    nets = _upload(runtime, h, np.float64)
    for first in range(0, len(out), CHUNK):
        last = min(first + CHUNK, len(out))
        res = runtime.buffer(cl.mem_flags.WRITE_ONLY, out[first:last].nbytes)
        kernel(queue, (last - first,), LOCAL, nets, *(_upload(runtime, a[first:last], t) for a, t in items), *extra,
               np.int64(last - first), res)
        cl.enqueue_copy(queue, out[first:last], res)
    queue.finish()
    return out

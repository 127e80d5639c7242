"""Per-coarse-triangle Loop stencils: the seed's recomputation model made data-parallel (one invocation per coarse
triangle, no communication between invocations, digest §A.4-A.5 with a modern data layout).

Loop subdivision is linear in the control points, and a coarse triangle's sub-triangles depend only on its 1-ring
(`loop_recompute`). So each coarse triangle's level-L vertices are a fixed matrix (its *stencil*) times its 1-ring's
points, in the order of their global ids. The matrix depends only on the patch's topology, creases and corners
(not on positions): it is computed once per distinct patch (`loop_recompute` on identity data), and regular
patches share one. A device then needs, per coarse triangle, the ids of its 1-ring points (the packed 1-ring)
and its stencil's id; it writes every vertex of its sub-triangles, shared vertices included: neighbours compute
them with the same weights in the same order, so they write the same bits.

`apply` is the numpy evaluation of the table; ``loop_stencil.cl`` (`apply_opencl`) the device one. Both equal
`loop.loop_subdivide` to float64 rounding (the weights are summed in another order than the factored steps).
"""

from dataclasses import dataclass

import numpy as np

from .loop_recompute import Recomputation


@dataclass
class StencilTable:
    """Stencils of every coarse triangle at one level.

    patch: (F, P) int64 global ids of each triangle's 1-ring points, sorted, padded with -1 to the largest patch P;
    outputs: (F, K) int64 global ids of the vertices of each triangle's sub-triangles (K = (2^L + 1)(2^L + 2) / 2),
    in the order of the stencil rows; stencil: (F,) int64 the stencil each triangle uses; weights: (S, K, P)
    float64 the stencils (rows: output vertices, columns: patch points, zero-padded); n_vertices: output count.
    """

    patch: np.ndarray
    outputs: np.ndarray
    stencil: np.ndarray
    weights: np.ndarray
    n_vertices: int
    triangles: np.ndarray  # (F * 4^L, 3) the welded output triangles


def build(positions, triangles, levels, creases=None, vertex_sharpness=None, boundary="EDGE_ONLY"):
    """The `StencilTable` of a mesh at ``levels`` (arguments as `loop.loop_subdivide`; positions only give the
    vertex count: stencils do not depend on them)."""
    n_v = len(positions)
    rec = Recomputation(np.zeros((n_v, 1)), triangles, levels, creases, vertex_sharpness, boundary)
    n_sub = 4**levels
    rows = (2**levels + 1) * (2**levels + 2) // 2
    n_f = len(rec.triangles)
    patches = [np.unique(rec.triangles[ring]) for ring in rec.rings]
    width = max(len(p) for p in patches)
    patch = np.full((n_f, width), -1, np.int64)
    outputs = np.empty((n_f, rows), np.int64)
    stencil = np.empty(n_f, np.int64)
    cache, weights = {}, []
    for t in range(n_f):
        verts = patches[t]
        patch[t, : len(verts)] = verts
        rec.values = np.zeros((n_v, len(verts)))
        rec.values[verts, np.arange(len(verts))] = 1.0  # identity on the patch: the rows are the weights
        ids, w = rec.patch(t)
        ids, w = ids.reshape(-1), w.reshape(-1, len(verts))
        order = np.unique(ids, return_index=True)[1]  # each output vertex once, by global id
        ids, w = ids[order], w[order]
        if len(ids) != rows:
            raise AssertionError(f"triangle {t}: {len(ids)} sub-vertices, expected {rows}")
        outputs[t] = ids
        key = w.tobytes()
        if key not in cache:
            cache[key] = len(weights)
            padded = np.zeros((rows, width))
            padded[:, : len(verts)] = w
            weights.append(padded)
        stencil[t] = cache[key]
    return StencilTable(patch, outputs, stencil, np.array(weights), rec.n_out,
                        rec.output_triangles[: n_f * n_sub])


def apply(table, values):
    """Evaluate every triangle's stencil on values (V, D) float64: (V_L, D) float64 (numpy reference)."""
    values = np.asarray(values, np.float64)
    gathered = np.where((table.patch >= 0)[..., None], values[np.maximum(table.patch, 0)], 0.0)  # (F, P, D)
    rows = np.einsum("fkp,fpd->fkd", table.weights[table.stencil], gathered)
    out = np.empty((table.n_vertices, values.shape[1]))
    out[table.outputs.ravel()] = rows.reshape(-1, values.shape[1])
    return out


def apply_opencl(runtime, table, values):
    """`apply` on an OpenCL device with double precision (``loop_stencil.cl``): one work item per coarse
    triangle. (V_L, D) float64."""
    cl = runtime.cl
    mf = cl.mem_flags
    values = np.ascontiguousarray(values, np.float64)
    if values.ndim == 1:
        values = values[:, None]

    def upload(a):
        return cl.Buffer(runtime.context, mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=np.ascontiguousarray(a))

    out = np.empty((table.n_vertices, values.shape[1]))
    dst = cl.Buffer(runtime.context, mf.WRITE_ONLY, out.nbytes)
    n_f, width_p = table.patch.shape
    kernel = runtime.kernel("subdivision/loop_stencil", "apply_stencils")
    kernel(runtime.queue, (n_f,), None, upload(table.patch), upload(table.outputs), upload(table.stencil),
           upload(table.weights), upload(values), dst, np.int32(n_f), np.int32(width_p),
           np.int32(table.outputs.shape[1]), np.int32(values.shape[1]))
    cl.enqueue_copy(runtime.queue, out, dst)
    runtime.queue.finish()
    return out

"""Per-coarse-triangle Loop stencils: [Concheiro et al.]'s recomputation model made data-parallel (one invocation per
coarse triangle, no communication between invocations, as in [Concheiro et al.], with a modern data layout).

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

from .loop import loop_subdivide
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
    vertex count: stencils do not depend on them).

    All patches are subdivided at once, as one mesh of disjoint copies (each patch's points numbered in global
    order, so every sum runs as in `loop_recompute`), carrying for each point the unit vector of its place in its
    patch: the subdivided values are the stencil rows.
    """
    n_v = len(positions)
    rec = Recomputation(np.zeros((n_v, 1)), triangles, levels, creases, vertex_sharpness, boundary)
    tris = rec.triangles
    n_f, n_sub = len(tris), 4**levels
    rows = (2**levels + 1) * (2**levels + 2) // 2
    local = [rec.local_patch(t) for t in range(n_f)]
    patches = [verts for verts, _, _ in local]
    sizes = np.array([len(p) for p in patches])
    width = int(sizes.max())
    first = np.concatenate([[0], np.cumsum(sizes)])  # each patch's first point in the union
    union_points = np.concatenate(patches)
    union_faces = np.concatenate([first[t] + faces for t, (_, faces, _) in enumerate(local)])
    face_first = np.concatenate([[0], np.cumsum([len(faces) for _, faces, _ in local])])
    own = face_first[:-1] + np.array([np.searchsorted(ring, t) for t, ring in enumerate(rec.rings)])
    identity = np.zeros((len(union_points), width))
    identity[np.arange(len(union_points)), np.arange(len(union_points)) - np.repeat(first[:-1], sizes)] = 1.0
    found = [(first[t] + c[0], c[1]) for t, (_, _, c) in enumerate(local) if c is not None and len(c[0])]
    union_creases = (np.concatenate([p for p, _ in found]), np.concatenate([v for _, v in found])) if found else None
    vs = None if vertex_sharpness is None else np.asarray(vertex_sharpness, np.float32)[union_points]
    result = loop_subdivide(np.zeros((len(union_points), 3)), union_faces, levels, creases=union_creases,
                            vertex_sharpness=vs, boundary=boundary, point_data={"w": identity}, dtype=np.float64,
                            backend="numpy")
    sub = (own[:, None] * n_sub + np.arange(n_sub)).ravel()
    union_ids = result.triangles[sub].reshape(n_f, -1)  # each triangle's sub-triangle corners in the union
    global_ids = rec.output_triangles.reshape(n_f, -1)
    order = np.argsort(global_ids, axis=1, kind="stable")
    sorted_global = np.take_along_axis(global_ids, order, axis=1)
    keep = np.concatenate([np.ones((n_f, 1), bool), np.diff(sorted_global, axis=1) > 0], axis=1)
    outputs = sorted_global[keep].reshape(n_f, rows).astype(np.int64)
    union_rows = np.take_along_axis(union_ids, order, axis=1)[keep].reshape(n_f, rows)
    w = result.point_attributes["w"].reshape(len(result.positions), width)[union_rows]  # (F, rows, width)
    patch = np.full((n_f, width), -1, np.int64)
    patch[np.arange(width)[None, :] < sizes[:, None]] = union_points
    flat = np.ascontiguousarray(w).reshape(n_f, -1)
    uniq, stencil = np.unique(flat, axis=0, return_inverse=True)
    return StencilTable(patch, outputs, stencil.reshape(-1).astype(np.int64), uniq.reshape(-1, rows, width),
                        rec.n_out, rec.output_triangles)


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

    def upload(a, dtype):
        return runtime.buffer(mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=np.ascontiguousarray(a, dtype))

    out = np.empty((table.n_vertices, values.shape[1]))
    dst = runtime.buffer(mf.WRITE_ONLY, out.nbytes)
    n_f, width_p = table.patch.shape
    kernel = runtime.kernel("subdivision/loop_stencil", "apply_stencils")
    i64, f64 = np.int64, np.float64
    kernel(runtime.queue, (n_f,), None, upload(table.patch, i64), upload(table.outputs, i64),
           upload(table.stencil, i64), upload(table.weights, f64), upload(values, f64), dst, np.int32(n_f),
           np.int32(width_p), np.int32(table.outputs.shape[1]), np.int32(values.shape[1]))
    cl.enqueue_copy(runtime.queue, out, dst)
    runtime.queue.finish()
    return out

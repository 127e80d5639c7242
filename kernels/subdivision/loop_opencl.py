"""Loop subdivision levels on an OpenCL device (``loop_level.cl``): the numpy reference's rules and numbering,
every level's topology built on the device, one read back at the end.

Taken for meshes whose creases and corners are all infinitely sharp (boundaries, Mark Sharp, crease 1, vertex
crease 1) on a device with double precision; semi-sharp creases stay on numpy (`supports`). Tests compare the
two paths on the same meshes.
"""

import numpy as np

from .loop_rules import SHARPNESS_INFINITE, correction_factor, correction_table

PROGRAM = "subdivision/loop_level"
LOCAL = 64


def supports(runtime, lv):
    """Whether ``runtime`` can subdivide `LoopLevel` ``lv`` (fp64, and no semi-sharp crease or corner)."""
    if runtime is None or "cl_khr_fp64" not in runtime.device.extensions:
        return False
    s, vs = lv.edge_sharpness, lv.vertex_sharpness
    return bool(np.all((s == 0) | (s >= SHARPNESS_INFINITE)) and np.all((vs == 0) | (vs >= SHARPNESS_INFINITE)))


def _incidence(lv):
    """Level-0 incident edges per vertex, by edge id: offsets (V + 1,) int32 and incident (2 E,) int32."""
    ends = lv.edges.ravel()
    order = np.argsort(ends, kind="stable")
    counts = np.bincount(ends, minlength=lv.n_vertices)
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int32)
    return offsets, (order // 2).astype(np.int32)


class _Run:
    def __init__(self, runtime):
        self.rt, self.cl = runtime, runtime.cl
        self.queue = runtime.queue

    def buf(self, nbytes):
        return self.rt.buffer(self.cl.mem_flags.READ_WRITE, max(int(nbytes), 1))

    def upload(self, array):
        a = np.ascontiguousarray(array)
        mf = self.cl.mem_flags
        return self.rt.buffer(mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=a if a.size else np.zeros(1))

    def fill(self, buf, value, count, dtype):
        self.cl.enqueue_fill_buffer(self.queue, buf, np.array(value, dtype), 0, int(count) * np.dtype(dtype).itemsize)

    def launch(self, name, n, *args):
        if n <= 0:
            return
        kernel = self.rt.kernel(PROGRAM, name)
        kernel(self.queue, (-(-int(n) // LOCAL) * LOCAL,), (LOCAL,), *args)

    def read(self, buf, shape, dtype):
        out = np.empty(shape, dtype)
        if out.size:
            self.cl.enqueue_copy(self.queue, out, buf)
        return out


def subdivide(runtime, lv, values, levels, progress=None):
    """Subdivide level-0 `LoopLevel` ``lv`` with values (V, D) float64 ``levels`` (>= 1) times on the device.

    Returns ``(values (V_L, D) float64, triangles (F, 3) int32, edges (E, 2) int32, face_edges (F, 3) int32,
    edge_sharpness (E,) float32)``, the same numbering as `loop.loop_subdivide`'s numpy path.
    """
    run = _Run(runtime)
    i32, u8 = np.int32, np.uint8
    n_v, n_e, n_f = lv.n_vertices, len(lv.edges), len(lv.triangles)
    width = values.shape[1]
    tris, fe = run.upload(lv.triangles.astype(i32)), run.upload(lv.face_edges.astype(i32))
    flip, side = run.upload(lv.flip.astype(u8)), run.upload(lv.side.astype(u8))
    edges = run.upload(lv.edges.astype(i32))
    sharp = run.upload((lv.edge_sharpness > 0).astype(u8))
    corner = (lv.vertex_sharpness > 0).astype(u8)
    offsets, incident = _incidence(lv)
    offsets_buf, incident_buf = run.upload(offsets), run.upload(incident)
    cf = run.upload(correction_table(max(int(lv.valence.max(initial=6)), 6)))
    src = run.upload(np.ascontiguousarray(values, np.float64))
    ints = lambda *xs: [i32(x) for x in xs]  # noqa: E731
    for step in range(levels):
        last = step == levels - 1
        edge_face, edge_local = run.buf(8 * n_e), run.buf(8 * n_e)
        run.fill(edge_face, -1, 2 * n_e, i32)
        run.launch("edge_faces", n_f, fe, side, edge_face, edge_local, i32(n_f))
        dst = run.buf(8 * width * (n_v + n_e))
        corner_buf = run.upload(corner)
        run.launch("odd_vertices", n_e, tris, edges, edge_face, edge_local, sharp, src, dst,
                   *ints(n_e, n_v, width), np.float64(correction_factor(6)))
        run.launch("even_vertices", n_v, edges, offsets_buf, incident_buf, sharp, corner_buf, cf, src, dst,
                   *ints(n_v, width))
        c_tris, c_fe = run.buf(4 * 12 * n_f), run.buf(4 * 12 * n_f)
        c_edges = run.buf(4 * 2 * (2 * n_e + 3 * n_f))
        c_flip, c_side = run.buf(12 * n_f), run.buf(12 * n_f)
        c_sharp = run.buf(2 * n_e + 3 * n_f)
        adjacency = i32(0 if last else 1)
        run.launch("refine_faces", n_f, tris, fe, flip, side, c_tris, c_fe, c_flip, c_side, c_edges, c_sharp,
                   *ints(n_f, n_v, n_e), adjacency)
        run.launch("refine_edges", n_e, edges, sharp, c_edges, c_sharp, *ints(n_e, n_v), adjacency)
        if last:
            c_sharp_host = np.repeat(run.read(sharp, n_e, u8), 2)
        else:
            c_offsets = np.concatenate([offsets, offsets[-1] + 6 * np.arange(1, n_e + 1, dtype=np.int64)])
            c_incident = run.buf(4 * int(c_offsets[-1]))
            run.launch("refine_incidence", n_v + n_e, edges, offsets_buf, incident_buf, edge_face, edge_local,
                       c_incident, *ints(n_v, n_e))
            offsets = c_offsets.astype(i32)
            offsets_buf, incident_buf = run.upload(offsets), c_incident
            corner = np.concatenate([corner, np.zeros(n_e, u8)])
        tris, fe, flip, side, edges, sharp, src = c_tris, c_fe, c_flip, c_side, c_edges, c_sharp, dst
        n_v, n_e, n_f = n_v + n_e, 2 * n_e + 3 * n_f, 4 * n_f
        if progress is not None:
            progress(step + 1, levels)
    out_values = run.read(src, (n_v, width), np.float64)
    out_tris = run.read(tris, (n_f, 3), i32)
    out_fe = run.read(fe, (n_f, 3), i32)
    out_edges = run.read(edges, (n_e, 2), i32)
    edge_sharpness = np.zeros(n_e, np.float32)
    edge_sharpness[: len(c_sharp_host)] = np.where(c_sharp_host > 0, SHARPNESS_INFINITE, 0.0)
    run.queue.finish()
    return out_values, out_tris, out_edges, out_fe, edge_sharpness

"""OpenCL paths of the tube kernel: frames (``tube_frames.cl``) and bodies (``tube_body.cl``).

Same numbering and values as the numpy reference in `builder` (tests compare them). The whole-mesh output
arrays are shared with the device (``USE_HOST_PTR``: no copy on a CPU device such as PoCL) and mapped back
once at the end.
"""

import numpy as np

from ..common.errors import OpenCLUnavailableError
from ..common.opencl_runtime import get_runtime
from .frames import has_fp64

BACKENDS = ("auto", "numpy", "opencl")


def runtime_for(backend):
    """The OpenCL runtime to use for ``backend``, or None for numpy."""
    if backend == "numpy":
        return None
    runtime = get_runtime()
    if runtime is not None and has_fp64(runtime):
        return runtime
    if backend == "opencl":
        raise OpenCLUnavailableError("The tube kernels need an OpenCL device with double precision (cl_khr_fp64)")
    return None


def segment_tables(run):
    """Per point of a `builder.CurveRun`: the segment starting there (-1 at an open curve's last point) and that
    segment's second point (0 where there is none): (P,) int32 each, written in order rather than scattered through
    ``run.seg`` (every point starts a segment but the last of an open curve; a cyclic curve's last segment closes
    it)."""
    counts = run.counts.astype(np.int64)
    ends = run.local[1:] - 1  # each curve's last point
    open_ = ~run.cyclic
    # segments before each curve: its points, less one for every open curve before it
    seg_of = np.arange(run.n_pts, dtype=np.int32)
    seg_of -= np.repeat((np.cumsum(open_) - open_).astype(np.int32), counts)
    nxt = np.arange(1, run.n_pts + 1, dtype=np.int32)
    nonempty = counts > 0
    last_open = ends[open_ & nonempty]
    seg_of[last_open], nxt[last_open] = -1, 0
    closing = run.cyclic & nonempty
    nxt[ends[closing]] = run.local[:-1][closing]
    return seg_of, nxt


class TubeDevice:
    """Writes tube bodies into ``mesh`` (a preallocated `builder.PolygonMesh`) with OpenCL."""

    OUTPUTS = ("positions", "point_normals", "edges", "corner_verts", "corner_edges", "face_offsets", "face_material",
               "corner_uvs")

    def __init__(self, runtime, mesh):
        self.runtime, self.mesh = runtime, mesh
        self.buffers, self._inputs = {}, []
        for name in self.OUTPUTS:
            host = getattr(mesh, name)
            if host is None or host.size == 0:
                host = np.zeros(1, np.float32)  # a placeholder argument (e.g. no UVs)
                setattr(self, f"_{name}_dummy", host)
            self.buffers[name] = runtime.shared(host)

    def _in(self, array, dtype):
        """An input buffer sharing host memory; the array is kept alive until `finish`."""
        a = np.ascontiguousarray(array, dtype=dtype)
        if a.size == 0:
            a = np.zeros(1, dtype)
        self._inputs.append(a)
        return self.runtime.shared(a, read_only=True)

    def write_body(self, lines, frames, n, curves, run, cursor, u_ends, ring):
        """One `builder.CurveRun` of tubes with ``n`` sides at the `builder.Cursor` (see `builder._write_body`);
        frames: `builder.TubeFrames`; u_ends: UV u at segment ends or None; ring: (n, 2) float32 cos, sin of the
        side angles."""
        pick, n_pts = run.pick, run.n_pts
        seg_of, nxt = segment_tables(run)
        none = np.zeros(1, np.float32)  # the kernel reads UVs and materials only when it writes them
        u0 = u1 = none
        if u_ends is not None:
            u0, u1 = np.zeros(n_pts, np.float32), np.zeros(n_pts, np.float32)
            u0[run.seg], u1[run.seg] = u_ends
        material = none.view(np.int32)
        if self.mesh.face_material is not None:
            material = lines.material_index[curves][run.curve_of_point]
        b = self.buffers
        kernel = self.runtime.kernel("tubes/tube_body", "tube_body")
        kernel(self.runtime.queue, (max(n_pts, 1),), None,
               self._in(lines.points[pick], np.float32), self._in(frames.n[pick], np.float32),
               self._in(frames.b[pick], np.float32), self._in(frames.radius[pick], np.float32),
               self._in(seg_of, np.int32), self._in(nxt, np.int32), self._in(u0, np.float32),
               self._in(u1, np.float32), self._in(material, np.int32), self._in(ring, np.float32),
               np.int32(n), np.int32(n_pts), np.int32(len(run.seg)), np.int64(cursor.v), np.int64(cursor.e),
               np.int64(cursor.f), np.int64(cursor.c), np.int32(u_ends is not None),
               np.int32(self.mesh.point_normals is not None), np.int32(self.mesh.face_material is not None),
               b["positions"], b["point_normals"], b["edges"], b["corner_verts"], b["corner_edges"], b["face_offsets"],
               b["face_material"], b["corner_uvs"])

    def finish(self):
        """Wait for the device and make its writes visible in the host arrays."""
        hosts = ((buf, getattr(self.mesh, name)) for name, buf in self.buffers.items())
        self.runtime.sync_to_host([(buf, host) for buf, host in hosts if host is not None and host.size])
        self._inputs.clear()

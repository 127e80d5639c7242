"""Evaluating attributes on a `Refinement`: weighted gathers, in numpy and OpenCL.

Point attributes (positions, vertex colours) are interpolated per output vertex, corner attributes
(UVs, corner normals, corner colours) per output face corner, and face attributes are copied from the
source face. Everything is linear interpolation, so an attribute that is an affine function of position
is reproduced exactly (up to float32 rounding of the result).
"""

import numpy as np

from ..common.errors import TesseraError
from ..common.opencl_runtime import get_runtime
from ..common.rows import take_rows
from .refine_templates import scatter_rows, stamp, triangle_starts

#: Below this many output rows the numpy path is used even when OpenCL is available (launch overhead).
OPENCL_MIN_ROWS = 1 << 15
BACKENDS = ("auto", "numpy", "opencl")
#: Faces per float64 product in `_slot_values` (keeps the temporary in cache).
CHUNK_FACES = 256
#: Rows per block of `gather_weighted_numpy` (its float64 temporaries stay in cache).
GATHER_CHUNK = 1 << 14


def weighted_sum(terms):
    """``sum(w * v)`` over the ``(w, v)`` pairs of ``terms`` in order, accumulated in float64: the one summation of
    the numpy paths (gathers, slot and corner sums, the surface's point path), so they all give the same bits.

    It starts from the first product and adds +0.0 last, which is bit for bit the sum from a +0 start: the two
    differ only in the sign of a zero sum, and a sum from +0 is never -0. Terms are flat runs or broadcast blocks.
    """
    pairs = iter(terms)
    w, v = next(pairs)
    acc = np.asarray(w * v, dtype=np.float64)
    for w, v in pairs:
        acc += w * v
    acc += 0.0
    return acc


def gather_weighted_numpy(values, idx, weights):
    """Reference weighted gather.

    values: (K, C) float; idx: (n, q) int; weights: (n, q) float. Returns (n, C) float32, accumulated in
    float64 and rounded once.
    """
    n, channels = len(idx), values.shape[1]
    taps = idx.shape[1]
    out = np.empty((n, channels), dtype=np.float32)
    if taps == 0:
        out[...] = 0.0
        return out
    # One channel at a time on flat runs: several times faster than gathering (n, C) rows per tap, the same bits.
    planes = [np.ascontiguousarray(values[:, c]) for c in range(channels)]
    for lo in range(0, n, GATHER_CHUNK):  # row block by row block (stays in cache)
        hi = min(n, lo + GATHER_CHUNK)
        i = [np.ascontiguousarray(idx[lo:hi, tap]) for tap in range(taps)]
        w = [np.ascontiguousarray(weights[lo:hi, tap]) for tap in range(taps)]
        for c, plane in enumerate(planes):
            out[lo:hi, c] = weighted_sum((w[tap], plane[i[tap]]) for tap in range(taps))
    return out


def gather_weighted_opencl(runtime, values, idx, weights):
    """The same gather as `gather_weighted_numpy` on an OpenCL device (float32 accumulation)."""
    cl = runtime.cl
    n, taps = idx.shape
    channels = values.shape[1]
    out = np.empty((n, channels), dtype=np.float32)
    if n == 0:
        return out
    mf = cl.mem_flags
    vals = np.ascontiguousarray(values, dtype=np.float32)
    ids = np.ascontiguousarray(idx, dtype=np.int32)
    wts = np.ascontiguousarray(weights, dtype=np.float32)
    d_vals = runtime.buffer(mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=vals)
    d_ids = runtime.buffer(mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=ids)
    d_wts = runtime.buffer(mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=wts)
    d_out = runtime.buffer(mf.WRITE_ONLY, out.nbytes)
    kernel = runtime.kernel("tessellation/gather_weighted", "gather_weighted")
    kernel(runtime.queue, (n,), None, d_vals, np.int32(channels), d_ids, d_wts, np.int32(taps), d_out, np.int32(n))
    cl.enqueue_copy(runtime.queue, out, d_out)
    return out


def gather_weighted(values, idx, weights, backend="auto"):
    """Weighted gather on the chosen backend: (K, C), (n, q), (n, q) -> (n, C) float32.

    backend: ``"auto"`` (OpenCL for large inputs when available, else numpy), ``"numpy"`` or ``"opencl"``.
    """
    if backend not in BACKENDS:
        raise TesseraError(f"Unknown compute backend {backend!r}; expected one of {', '.join(BACKENDS)}")
    if backend == "numpy" or len(idx) == 0:
        return gather_weighted_numpy(values, idx, weights)
    if backend == "auto" and len(idx) < OPENCL_MIN_ROWS:
        return gather_weighted_numpy(values, idx, weights)
    runtime = get_runtime()
    if runtime is None:
        if backend == "opencl":
            raise TesseraError("The OpenCL backend was requested but OpenCL is disabled or unavailable")
        return gather_weighted_numpy(values, idx, weights)
    return gather_weighted_opencl(runtime, values, idx, weights)


def point_values(ref, values, backend="auto"):
    """Interpolate a point attribute: (V, ...) -> (n_vertices, ...) float32.

    Input vertices are copied, edge points are ``(1 - t) a + t b`` in the edge's canonical direction,
    interior points are barycentric combinations of their face's corners.
    """
    values = np.asarray(values)
    if values.shape[0] != ref.n_corners:
        raise TesseraError(f"Point attribute has {values.shape[0]} rows; the mesh has {ref.n_corners} vertices")
    flat = values.reshape(ref.n_corners, -1)
    n_edge = len(ref.edge_point_edge)
    out = np.empty((ref.n_vertices, flat.shape[1]), dtype=np.float32)
    out[: ref.n_corners] = flat
    t = ref.edge_point_t
    out[ref.n_corners : ref.n_corners + n_edge] = gather_weighted(
        flat, ref.edges[ref.edge_point_edge], np.stack([1.0 - t, t], axis=1), backend
    )
    out[ref.n_corners + n_edge :] = gather_weighted(flat, ref.faces[ref.interior_face], ref.interior_bary, backend)
    return out.reshape((ref.n_vertices,) + values.shape[1:])


def corner_values(ref, values, backend="auto"):
    """Interpolate a per-face-corner attribute: (T, 3, ...) -> (M, 3, ...) float32."""
    values = np.asarray(values)
    n_faces = len(ref.faces)
    if values.shape[:2] != (n_faces, 3):
        raise TesseraError(f"Corner attribute has shape {values.shape}; expected ({n_faces}, 3, ...)")
    if ref.face_class is not None and backend != "opencl":
        return _corner_values_by_class(ref, values)
    if backend not in BACKENDS:
        raise TesseraError(f"Unknown compute backend {backend!r}; expected one of {', '.join(BACKENDS)}")
    if backend != "opencl":  # numpy wins here: no (3M, 3) index to build or upload
        return _corner_values_by_triangle(ref, values)
    flat = values.reshape(n_faces * 3, -1)
    source = ref.triangle_face.astype(np.int64)[:, None] * 3 + np.arange(3)  # (M, 3) source corners
    idx = np.repeat(source, 3, axis=0)  # one row per output corner
    out = gather_weighted(flat, idx, ref.corner_bary.reshape(-1, 3), backend)
    return out.reshape((ref.n_triangles, 3) + values.shape[2:])


def _corner_values_by_triangle(ref, values):
    """`corner_values` on a refinement built per face, in numpy: each output corner weighs its face's three corner
    values by its barycentrics. The same products and sums, in the same order, as `gather_weighted_numpy` over the
    corners, without building the (3M, 3) gather index. Where the refinement numbers its vertex slots (every
    construction here does) each slot is weighed once and gathered to its corners; the per-corner blocks below
    serve a refinement without slots and are the reference the tests hold the slot path to."""
    n_faces = len(ref.faces)
    flat = np.asarray(values).reshape(n_faces, 3, -1)
    tail = values.shape[2:]
    if ref.arrays.corner_slots is not None:  # each face's vertex weighed once, then gathered to its corners
        slot_face, slot_bary, triangle_slots = ref.arrays.corner_slots.get()
        sums = _slot_sums(flat, slot_face, slot_bary)  # (N, C) float32, gathered a row at a time
        return take_rows(sums, triangle_slots).reshape((ref.n_triangles, 3) + tail)
    out = np.empty((ref.n_triangles, 3, flat.shape[2]), dtype=np.float32)
    faces, bary = ref.triangle_face, ref.corner_bary
    step = max(1, GATHER_CHUNK // 3)
    for lo in range(0, ref.n_triangles, step):
        hi = min(ref.n_triangles, lo + step)
        src = flat[faces[lo:hi]]  # (n, 3, C): the face's corner values
        w = bary[lo:hi]  # (n, 3 output corners, 3 face corners)
        out[lo:hi] = weighted_sum((w[:, :, tap, None], src[:, None, tap, :]) for tap in range(3))
    return out.reshape((ref.n_triangles, 3) + tail)


def _slot_sums(flat, slot_face, slot_bary):
    """Each slot's weighted sum of its face's three corner values: flat (T, 3, C), slot_face (N,), slot_bary (N, 3)
    -> (N, C) float32; the products and sums of `_corner_values_by_triangle`, per slot instead of per corner.

    Worked one channel at a time on flat runs (a gather from a (T,) plane per tap), which numpy does several
    times faster than the (n, 3, C) blocks.
    """
    channels = flat.shape[2]
    out = np.empty((len(slot_face), channels), dtype=np.float32)
    planes = [[np.ascontiguousarray(flat[:, tap, c]) for tap in range(3)] for c in range(channels)]  # (T,) each
    for lo in range(0, len(slot_face), GATHER_CHUNK):
        hi = min(len(slot_face), lo + GATHER_CHUNK)
        faces = slot_face[lo:hi]
        w = [np.ascontiguousarray(slot_bary[lo:hi, tap]) for tap in range(3)]
        for c, taps in enumerate(planes):
            out[lo:hi, c] = weighted_sum((w[tap], taps[tap][faces]) for tap in range(3))
    return out


def _slot_values(ref, cls, values):
    """One class's corner attribute at every vertex slot of its faces (see `refine_templates.PatternClass`).

    values: (T, 3, C) float64. Returns (F, slots, C) float32. A corner copies its value; an edge point is
    ``(1 - t) a + t b`` along the mesh edge's canonical direction, so faces that agree at an edge's ends
    (no UV seam) get bit-identical values all along it; interior points are one matrix product.
    """
    v = values[cls.faces]  # (F, 3, C)
    n_faces, _, channels = v.shape
    e = cls.slot_edge
    p = len(cls.interior_bary)
    out = np.empty((n_faces, 3 + len(e) + p, channels), np.float32)
    out[:, :3] = v
    if len(e):
        points, flip = cls.edge_points(ref.face_edges, ref.flipped, ref.edge_point_start)  # (F, S) each
        t = ref.edge_point_t[points]
        # (1 - t) start + t end along the canonical direction, written as weights of the local edge's first and
        # second corner: the same two products and one (commutative) sum, so the same bits from either face.
        w_first, w_second = np.where(flip, t, 1.0 - t), np.where(flip, 1.0 - t, t)
        for c in range(channels):
            vc = v[:, :, c]
            out[:, 3 : 3 + len(e), c] = w_first * vc[:, e] + w_second * vc[:, (e + 1) % 3]
    if p:  # (F, 3C) @ (3C, pC): weights expanded per channel, so the product lands in (F, p, C) order
        expanded = np.zeros((3, channels, p, channels))
        for c in range(channels):
            expanded[:, c, :, c] = cls.interior_bary.T
        expanded = expanded.reshape(3 * channels, -1)
        flat = v.reshape(n_faces, -1)
        for lo in range(0, n_faces, CHUNK_FACES):  # a small float64 product, rounded into place (faster than
            hi = min(n_faces, lo + CHUNK_FACES)  # one product per channel written with a stride)
            out[lo:hi, 3 + len(e) :] = (flat[lo:hi] @ expanded).reshape(hi - lo, p, channels)
    return out


def _corner_values_by_class(ref, values):
    """`corner_values` for a refinement built per pattern class: each class's slot values stamped by its pattern."""
    n_faces = len(ref.faces)
    flat = values.reshape(n_faces, 3, -1).astype(np.float64)
    tail = values.shape[2:]
    if len(ref.classes) == 1:
        cls = ref.classes[0]
        return stamp(_slot_values(ref, cls, flat), cls.triangles.ravel()).reshape((ref.n_triangles, 3) + tail)
    starts = triangle_starts(ref.classes, n_faces)
    out = np.empty((ref.n_triangles, 3, flat.shape[2]), dtype=np.float32)
    for cls in ref.classes:
        block = stamp(_slot_values(ref, cls, flat), cls.triangles.ravel())
        scatter_rows(out, cls, starts, block.reshape(len(cls.faces), -1, 3, flat.shape[2]))
    return out.reshape((ref.n_triangles, 3) + tail)


def face_values(ref, values):
    """Copy a per-face attribute to the output triangles: (T, ...) -> (M, ...), dtype kept."""
    values = np.asarray(values)
    if values.shape[0] != len(ref.faces):
        raise TesseraError(f"Face attribute has {values.shape[0]} rows; the mesh has {len(ref.faces)} triangles")
    return values[ref.triangle_face]


def normalized(vectors):
    """Unit vectors along the last axis; zero vectors stay zero. (..., 3) -> (..., 3) float32.

    float32 input is normalised in float32 (within 2 ulp of unit length); anything else in float64.
    """
    v = np.asarray(vectors)
    out = v.astype(np.float32 if v.dtype == np.float32 else np.float64)  # a copy, normalised in place
    normalize_channels([out[..., c] for c in range(out.shape[-1])])
    return out.astype(np.float32, copy=False)


def normalize_channels(channels):
    """Normalise a vector field given as one array per component (same shapes), in place.

    Working per component keeps every operation on long runs of memory. Vectors of zero (or NaN) length
    become zero.
    """
    length = channels[0] * channels[0]
    for v in channels[1:]:
        length += v * v
    np.sqrt(length, out=length)
    bad = ~(length > 0)
    any_bad = bool(bad.any())
    length[bad] = 1.0
    for v in channels:
        v /= length
        if any_bad:
            v[bad] = 0.0

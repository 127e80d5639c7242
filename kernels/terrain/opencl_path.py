"""OpenCL path of the terrain analysis (``terrain_ham.cl``): HAM and tile table on the device.

Same definitions as the numpy reference in `terrain_analysis`; tests compare the two.
"""

import numpy as np


def ham_on_device(runtime, heights, inv_texel=1.0):
    """HAM of (H, W) float32 world heights scaled by ``inv_texel``: returns (ham device buffer, heights buffer)."""
    cl = runtime.cl
    h = np.ascontiguousarray(heights, np.float32)
    rows, width = h.shape
    mf = cl.mem_flags
    d_h = runtime.buffer(mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=h)
    d_m = runtime.buffer(mf.READ_WRITE, h.nbytes)
    d_ham = runtime.buffer(mf.READ_WRITE, h.nbytes)
    sobel = runtime.kernel("terrain/terrain_ham", "sobel_mag")
    size = (width, rows)
    sobel(runtime.queue, size, None, d_h, d_m, np.int32(width), np.int32(rows), np.float32(inv_texel))
    sobel(runtime.queue, size, None, d_m, d_ham, np.int32(width), np.int32(rows), np.float32(1.0))
    d_m.release()
    return d_ham, d_h


def ham(runtime, heights, inv_texel=1.0):
    """HAM as a host array: (H, W) float32."""
    d_ham, d_h = ham_on_device(runtime, heights, inv_texel)
    out = np.empty(np.shape(heights), np.float32)
    runtime.cl.enqueue_copy(runtime.queue, out, d_ham)
    d_h.release()
    d_ham.release()
    return out


def analyse_on_device(runtime, hm, table):
    """Fill every tile of ``table`` (a `terrain_analysis.TileTable`) from height map ``hm``."""
    cl = runtime.cl
    d_ham, d_h = ham_on_device(runtime, hm.heights(), 1.0 / hm.mean_texel)
    ntx, nty = table.counts
    rows, width = table.shape
    outs = [np.empty((nty, ntx), np.float32) for _ in range(3)] + [np.empty((nty, ntx), np.int32) for _ in range(2)]
    bufs = [runtime.buffer(cl.mem_flags.WRITE_ONLY, o.nbytes) for o in outs]
    stats = runtime.kernel("terrain/terrain_ham", "tile_stats")
    stats(runtime.queue, (ntx, nty), None, d_ham, d_h, np.int32(width), np.int32(rows), np.int32(table.tile_size),
          np.int32(ntx), np.int32(nty), *bufs)
    for o, b in zip(outs, bufs, strict=True):
        cl.enqueue_copy(runtime.queue, o, b)
        b.release()
    d_ham.release()
    d_h.release()
    table.ham_max[:], table.h_min[:], table.h_max[:], table.peak_x[:], table.peak_y[:] = outs

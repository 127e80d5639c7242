"""A displacement map kept on an OpenCL device between dabs ([Andrade 2012, §5.2], the interoperability layer).

`MapBuffer(runtime, map)` uploads the (H, W, C) float32 host map once. Each dab then runs on the device copy and
only its footprint rectangle comes back (`pull`), so a dab costs its footprint, not the map. The host array stays
the truth after every call; host-side edits (undo, loading a file) go back with `push`. Transfers are
rectangular copies (`clEnqueueReadBufferRect` and friends), correct on CPU and GPU devices alike.

A stroke may defer the read-back (`defer`): its dabs are queued one after another and their bounding box comes
back once at the end (`map_edit.flush_deferred`), so a dab costs its launch, not a launch and a wait. Until then
the device is ahead of the host; `push` and `smooth_all` refuse to run over such edits.
"""

from dataclasses import dataclass, field

import numpy as np

from ..common.errors import InvalidInputError, TesseraError
from .dab_timing import DabTimes
from .map_dabs import MAP_PROGRAM


@dataclass
class DeferredDab:
    """A dab run on the device whose footprint is not read back yet: what `map_edit.apply_dab` needs to run it
    again (``kind``, ``params`` a `DabParams`), its footprint ``region``, its OpenCL ``kernel`` name and, while it
    waits for a batched launch (`dab_batch`), its ``row`` of arguments (None once launched)."""

    kind: str
    params: object
    region: tuple
    kernel: str
    row: tuple | None = None


@dataclass
class DeferredDabs:
    """The device edits not read back yet: the bounding box ``region`` (x0, y0, x1, y1) and the dabs in order."""

    region: tuple
    dabs: list = field(default_factory=list)


class MapBuffer:
    """Device copy of one host map; ``host`` is the (H, W, C) float32 array it mirrors."""

    def __init__(self, runtime, dmap):
        if not isinstance(dmap, np.ndarray) or dmap.dtype != np.float32 or dmap.ndim != 3 \
                or not dmap.flags.c_contiguous:
            raise InvalidInputError("A device map mirrors a contiguous (height, width, channels) float32 array")
        self.runtime = runtime
        self.host = dmap
        cl = runtime.cl
        self.buf = runtime.buffer(cl.mem_flags.READ_WRITE | cl.mem_flags.COPY_HOST_PTR, hostbuf=dmap)
        self._scratch = None
        self._scratch_bytes = 0
        self._stamp = (None, None)  # (host array, device buffer) of the last stamp
        self._stale = None  # bounding box of host-side edits not yet on the device (see `mark_stale`)
        self.deferred = None  # `DeferredDabs`: device-side edits not yet on the host (see `defer`)
        self.dab_times = DabTimes()  # which side runs an ``auto`` dab of this map (`map_edit.apply_dab`)
        # which side runs an ``auto`` stroke (`map_strokes.run_stroke`): on the device its dabs are read back
        # together, so it is timed as a whole and tried on the device first
        self.stroke_times = DabTimes(prior_host_texels=0)

    @property
    def row_bytes(self):
        return self.host.shape[1] * self.host.shape[2] * 4

    def _rect(self, region):
        x0, y0, x1, y1 = region
        texel = self.host.shape[2] * 4
        return (x0 * texel, y0), ((x1 - x0) * texel, y1 - y0)

    def pull(self, region):
        """Copy the device rectangle ``(x0, y0, x1, y1)`` (end exclusive) into the host map."""
        origin, size = self._rect(region)
        self.runtime.cl.enqueue_copy(self.runtime.queue, self.host, self.buf, buffer_origin=origin,
                                     host_origin=origin, region=size, buffer_pitches=(self.row_bytes,),
                                     host_pitches=(self.row_bytes,))

    def pull_finite(self, region):
        """`pull` ``region`` only if every value there is finite; otherwise copy the host rectangle back to the
        device (undoing the device-side edit) and return False. Host and device agree either way."""
        origin, size = self._rect(region)
        x0, y0, x1, y1 = region
        tile = np.empty((y1 - y0, x1 - x0, self.host.shape[2]), np.float32)
        self.runtime.cl.enqueue_copy(self.runtime.queue, tile, self.buf, buffer_origin=origin, host_origin=(0, 0),
                                     region=size, buffer_pitches=(self.row_bytes,), host_pitches=(size[0],))
        if not np.isfinite(tile).all():
            self.push(region)
            return False
        self.host[y0:y1, x0:x1] = tile
        return True

    def defer(self, region, dab):
        """Note a device-side edit of ``region`` by ``dab`` (a `DeferredDab`) that the host does not have yet."""
        d = self.deferred
        if d is None:
            self.deferred = DeferredDabs(region, [dab])
            return
        r = d.region
        d.region = (min(r[0], region[0]), min(r[1], region[1]), max(r[2], region[2]), max(r[3], region[3]))
        d.dabs.append(dab)

    def take_deferred(self):
        """The `DeferredDabs` (or None), forgotten here: the caller reads them back."""
        d, self.deferred = self.deferred, None
        return d

    def _check_not_deferred(self, what):
        if self.deferred is not None:
            raise TesseraError(f"{what} would overwrite device edits not yet read back (map_edit.flush_deferred)")

    def mark_stale(self, region):
        """Note a host-side edit of ``region`` (x0, y0, x1, y1) that the device does not have yet; the next device
        operation copies it over first (`sync`). Many small edits then cost one copy, not one call each."""
        s = self._stale
        self._stale = region if s is None else (min(s[0], region[0]), min(s[1], region[1]), max(s[2], region[2]),
                                                max(s[3], region[3]))

    def sync(self):
        """Bring the device up to date with the host edits noted by `mark_stale`; returns the device buffer."""
        if self._stale is not None:
            self.push(self._stale)
        return self.buf

    def push(self, region=None):
        """Copy the host rectangle (default: all of it) to the device after a host-side edit."""
        self._check_not_deferred("Copying the host map to the device")
        h, w = self.host.shape[:2]
        if region is None or region == self._stale:
            self._stale = None
        origin, size = self._rect(region or (0, 0, w, h))
        self.runtime.cl.enqueue_copy(self.runtime.queue, self.buf, self.host, buffer_origin=origin,
                                     host_origin=origin, region=size, buffer_pitches=(self.row_bytes,),
                                     host_pitches=(self.row_bytes,))

    def snapshot(self, region):
        """A device buffer holding a tight copy of ``region`` (reused between calls): the halo of a smooth."""
        cl = self.runtime.cl
        origin, size = self._rect(region)
        nbytes = size[0] * size[1]
        if nbytes > self._scratch_bytes:
            self._scratch = self.runtime.buffer(cl.mem_flags.READ_WRITE, nbytes)
            self._scratch_bytes = nbytes
        cl.enqueue_copy(self.runtime.queue, self._scratch, self.buf, src_origin=origin, dst_origin=(0, 0),
                        region=size, src_pitches=(self.row_bytes,), dst_pitches=(size[0],))
        return self._scratch

    def smooth_all(self, strength, read_back=True):
        """Whole-map smooth on the device into the spare buffer, which then becomes the map; pulls the result
        (``read_back=False`` leaves the host stale: benchmarks of the device side only).

        Returns False, with host and device unchanged, when the map holds NaN or infinite values.
        """
        cl = self.runtime.cl
        h, w, c = self.host.shape
        self._check_not_deferred("A whole-map smooth")
        self.sync()
        if self._scratch_bytes != self.host.nbytes:
            self._scratch = self.runtime.buffer(cl.mem_flags.READ_WRITE, self.host.nbytes)
            self._scratch_bytes = self.host.nbytes
        bad = np.zeros(1, np.int32)
        d_bad = self.runtime.buffer(cl.mem_flags.READ_WRITE | cl.mem_flags.COPY_HOST_PTR, hostbuf=bad)
        n = w * c
        kernel = self.runtime.kernel(MAP_PROGRAM, "smooth_all")
        kernel(self.runtime.queue, ((n + 7) // 8, h), None, self.buf, self._scratch, d_bad, np.int32(n), np.int32(h),
               np.int32(c), np.float32(strength))
        cl.enqueue_copy(self.runtime.queue, bad, d_bad)
        if bad[0]:
            return False
        self.buf, self._scratch = self._scratch, self.buf  # ping-pong: the result becomes the map
        if read_back:
            cl.enqueue_copy(self.runtime.queue, self.host, self.buf)
        return True

    def stamp_buffer(self, stamp):
        """Device copy of a stamp map; the last one is kept while the same array is used."""
        if self._stamp[0] is not stamp:
            cl = self.runtime.cl
            self._stamp = (stamp, self.runtime.buffer(cl.mem_flags.READ_ONLY | cl.mem_flags.COPY_HOST_PTR,
                                            hostbuf=stamp))
        return self._stamp[1]

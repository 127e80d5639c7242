"""Large arrays written straight into the memory behind a new mesh's RNA collections.

``foreach_set`` copies through RNA on the Python thread: item by item where the property has a setter (face offsets,
~50 ns a face), otherwise as one copy that also pays the operating system's first touch of Blender's new pages. In
every supported Blender an item's RNA pointer (``as_pointer``) is its address in one contiguous array (attribute
values, face offsets), so `write_items` checks that layout (the stride and span of the item pointers), copies the
array in row blocks on the worker threads (numpy releases the GIL while it copies) and reads a sample back through
RNA; where the layout is not found, or the sample differs, it writes with ``foreach_set``. `item_view` and
`face_offsets_view` hand out that memory itself, for a kernel to write its output in place (`bridge.PolygonWriter`).
Large arrays are advised to take transparent huge pages before the first write (`kernels.common.huge_pages`: far
fewer page faults, where the system offers them).
For data-blocks the caller has just created only: nothing else may share or cache those arrays.
"""

import ctypes

import numpy as np

from ..kernels.common import huge_pages, workers
from . import compat

#: Arrays smaller than this go through ``foreach_set`` (the probe and the threads cost more than they save).
BULK_MIN_BYTES = 1 << 20
#: Face offsets go in bulk from 256 faces (their per-item setter makes ``foreach_set`` slow from the start).
OFFSETS_MIN_BYTES = 1024
#: Items read back through RNA after a bulk copy (spread over the array, the ends included).
SAMPLES = 17


def write_items(collection, prop, values, min_bytes=BULK_MIN_BYTES):
    """``collection.foreach_set(prop, values)``, in bulk where the layout allows.

    collection: an RNA collection of n items (``mesh.attributes[name].data``, ``mesh.polygons``); prop: the item
    property that holds the values; values: (n,) or (n, k) array of the item's C type (float32, int32, bool);
    min_bytes: smaller arrays go through ``foreach_set``. Returns True when the bulk copy was used.
    """
    values = np.ascontiguousarray(values)
    n = len(collection)
    if (n == 0) != (values.size == 0) or values.size % max(n, 1):
        raise ValueError(f"{values.shape} values for {n} items of {prop!r}")
    if n == 0:
        return False
    rows = values.reshape(n, -1)
    if n >= 2 and values.nbytes >= min_bytes:
        target = _item_array(collection, n, rows.dtype, rows.shape[1])
        if target is not None:
            _copy_blocks(target, rows)
            del target  # never kept: the memory is Blender's
            if sample_matches(collection, prop, rows):
                return True
    collection.foreach_set(prop, values.ravel())
    return False


def item_view(collection, dtype, width=1):
    """A writable numpy view (n, width) of the memory behind ``collection``'s n items, or None where its items are
    not one contiguous array of ``width`` values of ``dtype`` (or there are fewer than two items). For a
    data-block the caller has just created, to be written before anything else touches it and dropped after:
    the memory is Blender's (`sample_matches` checks what was written)."""
    n = len(collection)
    return _item_array(collection, n, np.dtype(dtype), width) if n >= 2 else None


def _item_array(collection, n, dtype, width):
    """A numpy view (n, width) of the memory behind ``collection`` when its items are one contiguous array of
    ``width`` values of ``dtype`` each; else None."""
    item = np.dtype(dtype).itemsize * width
    first, second, last = (collection[i].as_pointer() for i in (0, 1, n - 1))
    if first == 0 or second - first != item or last - first != item * (n - 1):
        return None
    memory = (ctypes.c_char * (item * n)).from_address(first)
    huge_pages.advise(first, item * n)  # not yet written: 2 MiB pages where the system offers them
    return np.frombuffer(memory, dtype=dtype).reshape(n, width)


def _copy_blocks(target, rows):
    """``target[...] = rows`` in one block per worker thread."""
    bounds = np.linspace(0, len(rows), workers.WORKERS + 1).astype(np.int64)
    jobs = [workers.submit(np.copyto, target[lo:hi], rows[lo:hi]) for lo, hi in zip(bounds[:-1], bounds[1:],
                                                                                        strict=True) if hi > lo]
    for job in jobs:
        job.result()


def sample_matches(collection, prop, rows):
    """Whether RNA reads back ``rows`` ((n, k) values) at `SAMPLES` items spread over ``collection``."""
    for i in np.unique(np.linspace(0, len(rows) - 1, SAMPLES).astype(np.int64)):
        got = getattr(collection[int(i)], prop)
        if not np.array_equal(np.asarray(got, dtype=rows.dtype).reshape(-1), rows[i]):
            return False
    return True


def set_face_offsets(mesh, starts):
    """Write the first corner of every face: starts (F,) int32 ascending, F = ``len(mesh.polygons)``, the corners
    already added (`write_items` on ``loop_start``, whose RNA setter costs ~50 ns a face; the last face's size is
    checked too, which reads the array's closing entry). Returns True when the bulk copy was used."""
    starts = np.ascontiguousarray(starts, dtype=np.int32)
    polys = mesh.polygons
    if len(starts) != len(polys):
        raise ValueError(f"{len(starts)} face starts for {len(polys)} faces")
    bulk = write_items(polys, "loop_start", starts, min_bytes=OFFSETS_MIN_BYTES)
    if bulk and polys[len(polys) - 1].loop_total != len(mesh.loops) - int(starts[-1]):
        polys.foreach_set("loop_start", starts)
        return False
    return bulk


def face_offsets_view(mesh):
    """A writable (F + 1,) int32 view of a new mesh's face offsets (each face's first corner, then the corner count:
    Blender's own layout, `compat.FACE_OFFSETS_CLOSED`), or None where they are not one array. Written in place, they
    are checked with `face_offsets_match`."""
    starts = item_view(mesh.polygons, np.int32) if compat.FACE_OFFSETS_CLOSED else None
    if starts is None:
        return None
    closed = (ctypes.c_char * (starts.nbytes + 4)).from_address(starts.ctypes.data)  # the starts and the count after
    return np.frombuffer(closed, dtype=np.int32)


def face_offsets_match(mesh, offsets):
    """Whether RNA reads ``offsets`` ((F + 1,) int32) back: the starts of `SAMPLES` faces and the last face's size."""
    polys = mesh.polygons
    last = len(polys) - 1
    if polys[last].loop_total != int(offsets[-1]) - int(offsets[-2]):
        return False
    return sample_matches(polys, "loop_start", offsets[:-1].reshape(-1, 1))

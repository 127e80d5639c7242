"""Many dabs of a stroke in one OpenCL launch, on a device-resident map (`map_buffer.MapBuffer`).

A DRAW, CONTACT, FORCE or NOISE dab changes each texel from that texel's value alone, so a stroke's dabs of these
kinds can run as one kernel over their bounding box in which every texel applies, in stroke order, the dabs that
reach it: the same float operations in the same order as one launch per dab, so the same bytes
(``map_dabs.cl``'s ``dabs_batch`` calls each single dab's texel function). The box is cut into square bins a
quarter of the largest footprint wide (8 to 1024 texels), and each bin lists the dabs whose footprint overlaps it,
so a texel looks at the ten or so dabs near it rather than at all of them. One launch replaces a launch per dab:
a launch costs its arguments and a wake-up of the device's worker threads, which is most of a small dab; large
footprints (over `MAX_TEXELS`) keep a launch each. ``bench/displacement.py`` (``stroke``, ``stroke_kinds``) measures
strokes; ``docs/performance.md`` keeps the figures. The work-groups
are one row of up to 64 texels inside one bin, so the texels of a group loop over the same dabs.
"""

import numpy as np

from .map_dabs import MAP_PROGRAM

#: single-dab kernels with a batched form, and their kind code in ``dabs_batch``
BATCHED = {"draw": 0, "contact": 1, "force": 2, "noise": 3}
#: Footprints of more texels run a launch each (still read back with the stroke): the batched kernel does more per
#: texel and dab (parameters loaded, not arguments), which outweighs the launches saved from a radius of about 32
#: (65² texels) on, where the two tie on PoCL (measured when this limit was chosen; `bench/displacement.py`).
MAX_TEXELS = 64 * 64
MIN_BIN, MAX_BIN = 8, 1024
FLOATS, INTS = 12, 3  # per dab in ``dabs_batch``


def row(kernel, args):
    """What ``dabs_batch`` needs of one dab of ``kernel`` whose single-dab scalar arguments are ``args`` (as
    `map_edit.DabPlan.args`): ((FLOATS,) float32, (INTS,) int32), the kind code first among the ints, then the
    kernel's arguments in order (floats and ints apart; NOISE's uint32 seed as its int32 bits)."""
    floats, ints = np.zeros(FLOATS, np.float32), np.zeros(INTS, np.int32)
    ints[0] = BATCHED[kernel]
    pos = args[0]
    if kernel in ("draw", "noise"):
        _, radius, strength, falloff, vec = args[:5]
        values = [pos["x"], pos["y"], radius, strength, vec["x"], vec["y"], vec["z"], vec["w"]]
        ints[1] = falloff
        if kernel == "noise":
            values.append(args[5])  # cell
            ints[2] = np.uint32(args[6]).view(np.int32)  # seed
    elif kernel == "contact":
        values = [pos["x"], pos["y"], args[1], args[2]]  # depth, radius
    else:  # force
        f, area = args[1], args[2]
        values = [pos["x"], pos["y"], f["x"], f["y"], f["z"], f["w"], area]
    floats[: len(values)] = values
    return floats, ints


def bin_size(regions):
    """The bin edge for footprints ``regions`` (n, 4) int64 (x0, y0, x1, y1): a power of two near a quarter of the
    largest footprint side, clamped to [MIN_BIN, MAX_BIN]."""
    side = int(max((regions[:, 2] - regions[:, 0]).max(), (regions[:, 3] - regions[:, 1]).max()))
    return int(np.clip(1 << max(side // 4, 1).bit_length() - 1, MIN_BIN, MAX_BIN))


def bins(regions, box, size):
    """The dabs of each bin, in dab order.

    ``regions`` (n, 4) int64 footprints (x0, y0, x1, y1, end exclusive) inside ``box`` (x0, y0, x1, y1); bins of
    ``size`` texels, ``bins_x`` to a row from the box's corner. Returns (bin_start (bins + 1,) int32, bin_dabs (m,)
    int32, bins_x): bin b holds dabs bin_dabs[bin_start[b]:bin_start[b + 1]].
    """
    bx0, by0, bx1, by1 = box
    bins_x, bins_y = -(-(bx1 - bx0) // size), -(-(by1 - by0) // size)
    tx0, ty0 = (regions[:, 0] - bx0) // size, (regions[:, 1] - by0) // size
    nx = (regions[:, 2] - 1 - bx0) // size - tx0 + 1
    ny = (regions[:, 3] - 1 - by0) // size - ty0 + 1
    counts = nx * ny
    dab_of = np.repeat(np.arange(len(regions)), counts)
    k = np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
    width = nx[dab_of]
    b = (ty0[dab_of] + k // width) * bins_x + tx0[dab_of] + k % width
    bin_dabs = dab_of[np.argsort(b, kind="stable")].astype(np.int32)
    bin_start = np.zeros(bins_x * bins_y + 1, np.int32)
    np.cumsum(np.bincount(b, minlength=bins_x * bins_y), out=bin_start[1:])
    return bin_start, bin_dabs, bins_x


def launch(device, rows, regions):
    """Queue ``dabs_batch`` for dabs ``rows`` (from `row`, in stroke order) with footprints
    ``regions`` on ``device`` (a `MapBuffer`, brought up to date with host edits first). Returns the bounding box;
    nothing is read back."""
    rt = device.runtime
    mf = rt.cl.mem_flags
    regions = np.asarray(regions, np.int64).reshape(-1, 4)
    box = (int(regions[:, 0].min()), int(regions[:, 1].min()), int(regions[:, 2].max()), int(regions[:, 3].max()))
    size = bin_size(regions)
    bin_start, bin_dabs, bins_x = bins(regions, box, size)
    floats = np.stack([r[0] for r in rows])
    ints = np.stack([r[1] for r in rows])
    inputs = [rt.buffer(mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=a)
              for a in (floats, ints, bin_start, bin_dabs)]
    x0, y0, x1, y1 = box
    h, w, channels = device.host.shape
    group = min(size, 64)  # a row of a bin: the group's texels loop over the same dabs
    gsize = (-(-(x1 - x0) // group) * group, y1 - y0)
    rt.kernel(MAP_PROGRAM, "dabs_batch")(
        rt.queue, gsize, (group, 1), device.sync(), np.int64((y0 * w + x0) * channels), np.int32(w),
        np.int32(channels), np.int32(x0), np.int32(y0), np.int32(x1 - x0), np.int32(y1 - y0), *inputs,
        np.int32(size), np.int32(bins_x))
    return box

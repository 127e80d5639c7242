"""No-data voids of elevation data: filled from their valid neighbours, or cut out of the mesh as holes.

A void (the file's no-data value, NaN, or a place no file covers) never reaches the terrain as a height. The
grid is scanned once in bands and cut into cells of `CELL` samples; the cells holding voids are grouped into
8-connected components, and each component is filled inside its window (its cells' bounding box grown by one
cell of valid samples on every side) by **pull-push interpolation** [Gortler 1996, §3.6]: the window is pulled
down a pyramid of 2×2 weighted means (weights: the share of valid samples, capped at 1) until no level has a
gap, then pushed back up, each level keeping its own weighted value and taking the rest from the bilinear
upsampling of the level above. Every filled value is a weighted mean of valid samples (it lies within their
range); valid samples keep their bits. The result depends only on the samples of the whole grid (the cells are
counted from its corner), so a DEM split over several files fills exactly as the single file does.

With ``cut=True`` the voids are filled the same way, so the height analysis, the tile levels and the screen
error see smooth ground, and `FilledGrid.void_at` tells the mesh which triangles to drop (any corner that reads
a void sample). Memory: one band of `CELL` rows while scanning, then each component's window, checked with the
filled values kept so far against the budget before it is read. A void too large for the budget is refused
when filled, and given the mean of the valid samples in its window (read band by band) when cut: its inside is
never shown.

The filled values are kept per void cell (a thin void across the map costs its cells, not its bounding box).
`FilledGrid.save_index` writes them with the cell labels to a **void index** file (`VoidIndex`): the tasks of a farm
split read it instead of scanning, each reading only the cells its windows meet, so a task reads only its own part
of the data while every filled value stays the one the whole scan gives.
"""

import json
import os
from collections import OrderedDict

import numpy as np

from ..common.budget import check_bytes
from ..common.errors import BudgetError, InvalidInputError
from .sample_grid import HeldWindow, SampleGrid

#: Cell side in samples: voids are found per cell, and a component's window grows by one cell each side.
CELL = 64
#: Bytes per window sample while filling (float64 values and weights over the pyramid, and a float32 result).
FILL_BYTES_PER_SAMPLE = 64


def pull_push(values, valid):
    """Fill the samples of ``values`` (h, w) where ``valid`` (h, w) bool is False: (h, w) float32 (valid samples
    unchanged). Needs at least one valid sample."""
    levels = []
    w = valid.astype(np.float64)
    v = np.where(valid, values, 0.0).astype(np.float64)
    while True:
        levels.append((v, w))
        if w.min() > 0 or v.shape == (1, 1):
            break
        ph, pw = v.shape[0] % 2, v.shape[1] % 2
        vw = np.pad(v * w, ((0, ph), (0, pw)))
        wp = np.pad(w, ((0, ph), (0, pw)))
        ws = wp[0::2, 0::2] + wp[1::2, 0::2] + wp[0::2, 1::2] + wp[1::2, 1::2]
        vs = vw[0::2, 0::2] + vw[1::2, 0::2] + vw[0::2, 1::2] + vw[1::2, 1::2]
        v = np.where(ws > 0, vs / np.where(ws > 0, ws, 1.0), 0.0)
        w = np.minimum(ws, 1.0)
    up = levels[-1][0]
    for v, w in reversed(levels[:-1]):
        up = w * v + (1.0 - w) * _upsample(up, v.shape)
    return np.where(valid, values, up).astype(np.float32)


def _upsample(coarse, shape):
    """Bilinear upsampling of a level to the next finer one, ``shape`` (h, w): sample i of the fine level sits at
    (i + 0.5) / 2 - 0.5 of the coarse one (clamped at the borders)."""
    def axis(n_fine, n_coarse):
        t = np.clip((np.arange(n_fine) + 0.5) / 2.0 - 0.5, 0.0, n_coarse - 1)
        i0 = np.minimum(np.floor(t).astype(np.int64), max(n_coarse - 2, 0))
        i1 = np.minimum(i0 + 1, n_coarse - 1)
        return i0, i1, t - i0

    y0, y1, fy = axis(shape[0], coarse.shape[0])
    x0, x1, fx = axis(shape[1], coarse.shape[1])
    top = coarse[y0][:, x0] * (1 - fx) + coarse[y0][:, x1] * fx
    bottom = coarse[y1][:, x0] * (1 - fx) + coarse[y1][:, x1] * fx
    return top * (1 - fy)[:, None] + bottom * fy[:, None]


def label_cells(mask):
    """8-connected components of a small bool array: (labels (same shape) int32, 0 outside, 1.. inside; count).

    Each cell starts with its own index as label; every round takes the least label among the 3 x 3 neighbours, then
    jumps each label to the label of the cell it names (pointer jumping: a label always names a cell of the same
    component), so a long winding component settles in few rounds."""
    h, w = mask.shape
    big = h * w + 1
    inside = mask.ravel()
    lab = np.where(mask, np.arange(1, h * w + 1, dtype=np.int64).reshape(h, w), big)
    while True:
        p = np.pad(lab, 1, constant_values=big)
        low = lab.copy()
        for dy in (0, 1, 2):
            for dx in (0, 1, 2):
                np.minimum(low, p[dy:dy + h, dx:dx + w], out=low)
        flat = np.where(mask, low, big).ravel()
        while True:
            jumped = flat.copy()
            jumped[inside] = flat[flat[inside] - 1]
            if np.array_equal(jumped, flat):
                break
            flat = jumped
        low = flat.reshape(h, w)
        if np.array_equal(low, lab):
            break
        lab = low
    ids, out = np.unique(np.where(mask, lab, 0), return_inverse=True)
    out = out.reshape(h, w).astype(np.int32)
    if ids[0] != 0:  # every cell holds a void: no 0 among the labels
        out += 1
    return out, len(ids) - 1 if ids[0] == 0 else len(ids)


class FilledGrid(SampleGrid):
    """A grid's samples with its voids filled (see the module docstring): (H, W) float32, row 0 at the bottom.

    raw: a `SampleGrid` whose voids are NaN; cut: voids become holes in the mesh (`void_at`); budget_bytes: the
    memory budget a component's window must fit (0: none); name: the data's name, for messages;
    progress(done, total): called after each scanned band; index: a `VoidIndex` made of this grid before (by
    `save_index`, e.g. once for every task of a farm): its voids and filled values are taken from it, and nothing is
    scanned, so a window reads only the raw samples it covers and the filled cells inside it.

    The filled values are kept per cell of `CELL` samples (the cells that hold voids; a component too large to fill
    gives all its cells one value): a void sample takes its cell's value at its place.
    """

    def __init__(self, raw, cut=False, budget_bytes=0, name="the elevation data", progress=None, index=None):
        self.raw, self.cut, self.name = raw, bool(cut), name
        self.shape = raw.shape
        h, w = self.shape
        if index is not None:
            index.check(self.shape, self.cut, name)
            self.labels, self.void_count, self._cells = index.labels, index.void_count, index
            return
        ncy, ncx = -(-h // CELL), -(-w // CELL)
        counts = np.zeros((ncy, ncx), np.int64)
        starts = np.arange(0, w, CELL)
        for cy in range(ncy):
            band = raw.band(cy * CELL, min(h, (cy + 1) * CELL))
            counts[cy] = np.add.reduceat(np.isnan(band).sum(0), starts)
            if progress is not None:
                progress(cy + 1, ncy)
        self.void_count = int(counts.sum())
        if self.void_count == h * w:
            raise InvalidInputError(f"Every sample of {name} is no-data: there is no height to build a terrain from")
        self.labels, n = label_cells(counts > 0)
        self._kept = 0  # bytes of filled values kept so far
        self._cells = CellValues(self.labels)
        for k in range(1, n + 1):
            self._fill_component(k, budget_bytes)

    def _fill_component(self, k, budget_bytes):
        h, w = self.shape
        cy, cx = np.nonzero(self.labels == k)
        y0, y1 = int(cy.min()) * CELL, min(h, (int(cy.max()) + 1) * CELL)
        x0, x1 = int(cx.min()) * CELL, min(w, (int(cx.max()) + 1) * CELL)
        wy0, wy1, wx0, wx1 = max(0, y0 - CELL), min(h, y1 + CELL), max(0, x0 - CELL), min(w, x1 + CELL)
        need = (wy1 - wy0) * (wx1 - wx0) * FILL_BYTES_PER_SAMPLE + self._kept
        try:
            check_bytes(need, budget_bytes, f"A no-data void of {name_size(x1 - x0, y1 - y0)} in {self.name} would "
                        "be filled", "No-Data: Holes")
        except BudgetError:
            if not self.cut:
                raise
            # never shown: the analysis sees the mean of the valid ground in the window
            self._cells.means[k] = self._window_mean(wy0, wy1, wx0, wx1)
            return
        self._kept += cy.size * CELL * CELL * 4
        window = self.raw.window(wy0, wy1, wx0, wx1)
        valid = ~np.isnan(window)
        if not valid.any():  # the component fills its whole window only when it is the whole grid: refused above
            raise InvalidInputError(f"A no-data void in {self.name} has no valid sample around it")
        filled = pull_push(np.where(valid, window, 0.0), valid)
        for i, j in zip(cy.tolist(), cx.tolist(), strict=True):
            r, c = i * CELL - wy0, j * CELL - wx0
            self._cells.values[(i, j)] = filled[r:r + CELL, c:c + CELL]

    def _window_mean(self, wy0, wy1, wx0, wx1):
        """The mean of the valid samples in a window, read band by band: float32."""
        total, count = 0.0, 0
        for r in range(wy0, wy1, CELL):
            band = self.raw.window(r, min(wy1, r + CELL), wx0, wx1)
            valid = band[~np.isnan(band)]
            total, count = total + float(valid.astype(np.float64).sum()), count + valid.size
        if count == 0:
            raise InvalidInputError(f"A no-data void in {self.name} has no valid sample around it")
        return np.float32(total / count)

    def window(self, y0, y1, x0, x1):
        out = self.raw.window(y0, y1, x0, x1)
        void = np.isnan(out)
        if not void.any():
            return out
        out = out.copy() if not out.flags.writeable else out
        cy0, cx0 = y0 // CELL, x0 // CELL
        for i, j in np.argwhere(self.labels[cy0:(y1 - 1) // CELL + 1, cx0:(x1 - 1) // CELL + 1] > 0).tolist():
            cy, cx = cy0 + i, cx0 + j
            a, b = max(y0, cy * CELL), min(y1, (cy + 1) * CELL)
            c, d = max(x0, cx * CELL), min(x1, (cx + 1) * CELL)
            take = void[a - y0:b - y0, c - x0:d - x0]
            if take.any():
                values = self._cells.cell(cy, cx)[a - cy * CELL:b - cy * CELL, c - cx * CELL:d - cx * CELL]
                out[a - y0:b - y0, c - x0:d - x0][take] = values[take]
        return out

    def points(self, ys, xs):
        out = self.raw.points(ys, xs).astype(np.float32, copy=True)
        void = np.isnan(out)
        if void.any():
            vy, vx = ys[void], xs[void]
            cy, cx = vy // CELL, vx // CELL
            key = cy * self.labels.shape[1] + cx
            got = np.empty(vy.shape, np.float32)
            for k in np.unique(key).tolist():
                sel = key == k
                i, j = divmod(k, self.labels.shape[1])
                got[sel] = self._cells.cell(i, j)[vy[sel] - i * CELL, vx[sel] - j * CELL]
            out[void] = got
        return out

    def void_at(self, x, y):
        """Whether a point at sample coordinates ``x, y`` (float arrays, inside the grid) reads a void sample in its
        bilinear footprint: bool array. All False unless the voids are cut."""
        x, y = np.asarray(x, np.float64), np.asarray(y, np.float64)
        out = np.zeros(np.broadcast(x, y).shape, bool)
        if not self.cut or self.void_count == 0:
            return out
        for fy in (np.floor, np.ceil):
            for fx in (np.floor, np.ceil):
                out |= np.isnan(self.raw.points(fy(y).astype(np.int64), fx(x).astype(np.int64)))
        return out

    def hold(self, y0, y1, x0, x1):
        """Read the raw samples of rows ``[y0, y1)``, columns ``[x0, x1)`` once and keep them (`HeldWindow`): every
        later read inside them (windows, points, `void_at`) decodes nothing again."""
        self.raw = HeldWindow(getattr(self.raw, "grid", self.raw), y0, y1, x0, x1)

    def save_index(self, path, source=""):
        """Write this grid's voids and filled values to ``path`` (see `VoidIndex`); ``source`` identifies the data
        (`VoidIndex.check` compares it). The caller makes the write whole (a temporary name, then a rename)."""
        header = {"format": INDEX_FORMAT, "shape": list(self.shape), "cell": CELL, "cut": self.cut,
                  "void_count": self.void_count, "source": source,
                  "means": {str(k): float(v) for k, v in self._cells.means.items()}}
        keys = sorted(self._cells.values)
        slots = np.full(self.labels.shape, -1, np.int64)
        for n, key in enumerate(keys):
            slots[key] = n
        with open(path, "wb") as f:
            np.save(f, np.frombuffer(json.dumps(header).encode(), np.uint8))
            np.save(f, self.labels.astype(np.int32))
            np.save(f, slots)
            np.lib.format.write_array_header_2_0(f, {"descr": "<f4", "fortran_order": False,
                                                     "shape": (len(keys), CELL, CELL)})
            for key in keys:
                cell = np.full((CELL, CELL), np.nan, "<f4")
                v = self._cells.values[key]
                cell[:v.shape[0], :v.shape[1]] = v
                f.write(cell.tobytes())
            f.flush()
            os.fsync(f.fileno())


#: The void index's format name and version (a file of another version is refused, not misread).
INDEX_FORMAT = "tessera-voids-1"


class CellValues:
    """The filled values of a grid's void cells: ``values`` (cell row, cell column) -> (CELL, CELL) float32 (clipped
    at the grid's edge), ``means`` component label -> the one value of a component too large to fill."""

    def __init__(self, labels):
        self.labels = labels
        self.values, self.means = {}, {}

    def cell(self, cy, cx):
        """The filled values of void cell (cy, cx): (CELL, CELL) float32 or smaller at the grid's edge."""
        got = self.values.get((cy, cx))
        if got is None:
            return np.full((CELL, CELL), self.means[int(self.labels[cy, cx])], np.float32)
        return got


class VoidIndex(CellValues):
    """A void index file (`FilledGrid.save_index`): the cell labels, the count of void samples and the filled values
    of the void cells, read a cell at a time (``os.pread``) as the windows of one task ask for them.

    Layout: four .npy arrays one after the other: the JSON header (uint8), the labels (ncy, ncx) int32, the slots
    (ncy, ncx) int64 (the cell's place among the values, -1: none stored), the values (n, CELL, CELL) float32."""

    #: Cells kept after reading (64 MiB).
    KEEP = 4096

    def __init__(self, path):
        self.path = path
        name = os.path.basename(path)
        try:
            with open(path, "rb") as f:
                header = json.loads(np.load(f, allow_pickle=False).tobytes())
                if header.get("format") != INDEX_FORMAT:
                    raise ValueError(f"format {header.get('format')!r}, not {INDEX_FORMAT}")
                labels = np.load(f, allow_pickle=False)
                self.slots = np.load(f, allow_pickle=False)
                fmt = np.lib.format
                version = fmt.read_magic(f)
                read_header = fmt.read_array_header_1_0 if version == (1, 0) else fmt.read_array_header_2_0
                shape, _, dtype = read_header(f)
                self._offset = f.tell()
                size = os.fstat(f.fileno()).st_size
        except (OSError, ValueError, KeyError, EOFError, UnicodeDecodeError) as err:
            reason = err.strerror if isinstance(err, OSError) and err.strerror else str(err) or type(err).__name__
            raise InvalidInputError(f"The void index {name} cannot be read ({reason}): make the farm plan again, "
                                    "which writes it") from None
        n = int(np.count_nonzero(self.slots >= 0))
        if (dtype != np.dtype("<f4") or tuple(shape) != (n, CELL, CELL) or header.get("cell") != CELL
                or size != self._offset + n * CELL * CELL * 4 or labels.shape != self.slots.shape):
            raise InvalidInputError(f"The void index {name} is cut short or damaged: make the farm plan again, which "
                                    "writes it")
        super().__init__(labels)
        self.header = header
        self.void_count = int(header["void_count"])
        self.means = {int(k): np.float32(v) for k, v in header["means"].items()}
        self._loaded = OrderedDict()

    def check(self, shape, cut, name):
        """Refuse this index for a grid of another ``shape`` or void treatment (``cut``)."""
        if tuple(self.header["shape"]) != tuple(shape):
            raise InvalidInputError(f"The void index {os.path.basename(self.path)} was made for "
                                    f"{name_size(*self.header['shape'][::-1])}, not the {name_size(*shape[::-1])} of "
                                    f"{name}: make the farm plan again for this data")
        if bool(self.header["cut"]) != bool(cut):
            made = "cut out as holes" if self.header["cut"] else "filled"
            raise InvalidInputError(f"The void index {os.path.basename(self.path)} has the voids {made}; this task "
                                    f"asks otherwise (No-Data): make the farm plan again with the task's settings")

    def cell(self, cy, cx):
        slot = int(self.slots[cy, cx])
        if slot < 0:
            return super().cell(cy, cx)
        got = self._loaded.get(slot)
        if got is None:
            nbytes = CELL * CELL * 4
            fd = os.open(self.path, os.O_RDONLY)
            try:
                data = os.pread(fd, nbytes, self._offset + slot * nbytes)
            finally:
                os.close(fd)
            if len(data) != nbytes:
                raise InvalidInputError(f"The void index {os.path.basename(self.path)} is cut short: make the farm "
                                        "plan again, which writes it")
            h, w = self.header["shape"]
            got = np.frombuffer(data, "<f4").reshape(CELL, CELL)[:h - cy * CELL, :w - cx * CELL]
            self._loaded[slot] = got
            while len(self._loaded) > self.KEEP:
                self._loaded.popitem(last=False)
        else:
            self._loaded.move_to_end(slot)
        return got


def name_size(w, h):
    """``"W x H samples"`` for messages."""
    return f"{w:,} x {h:,} samples"

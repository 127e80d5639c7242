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
"""

import numpy as np

from ..common.budget import check_bytes
from ..common.errors import BudgetError, InvalidInputError
from .sample_grid import SampleGrid

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
    progress(done, total): called after each scanned band.
    """

    def __init__(self, raw, cut=False, budget_bytes=0, name="the elevation data", progress=None):
        self.raw, self.cut, self.name = raw, bool(cut), name
        self.shape = raw.shape
        h, w = self.shape
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
        self.patches = []  # per component k (index k - 1): (y0, x0, values (h, w) float32)
        for k in range(1, n + 1):
            self.patches.append(self._fill_component(k, budget_bytes))

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
            return y0, x0, np.broadcast_to(self._window_mean(wy0, wy1, wx0, wx1), (y1 - y0, x1 - x0))
        self._kept += (y1 - y0) * (x1 - x0) * 4
        window = np.concatenate([self.raw.band(r, min(wy1, r + CELL))[:, wx0:wx1] for r in range(wy0, wy1, CELL)])
        valid = ~np.isnan(window)
        if not valid.any():  # the component fills its whole window only when it is the whole grid: refused above
            raise InvalidInputError(f"A no-data void in {self.name} has no valid sample around it")
        filled = pull_push(np.where(valid, window, 0.0), valid)
        return y0, x0, filled[y0 - wy0:y1 - wy0, x0 - wx0:x1 - wx0]

    def _window_mean(self, wy0, wy1, wx0, wx1):
        """The mean of the valid samples in a window, read band by band: float32."""
        total, count = 0.0, 0
        for r in range(wy0, wy1, CELL):
            band = self.raw.band(r, min(wy1, r + CELL))[:, wx0:wx1]
            valid = band[~np.isnan(band)]
            total, count = total + float(valid.astype(np.float64).sum()), count + valid.size
        if count == 0:
            raise InvalidInputError(f"A no-data void in {self.name} has no valid sample around it")
        return np.float32(total / count)

    def _texel_labels(self, ys, xs):
        return self.labels[ys // CELL, xs // CELL]

    def band(self, y0, y1):
        out = self.raw.band(y0, y1)
        void = np.isnan(out)
        if not void.any():
            return out
        out = out.copy() if not out.flags.writeable else out
        for k, (py, px, values) in enumerate(self.patches, 1):
            a, b = max(y0, py), min(y1, py + values.shape[0])
            if a >= b:
                continue
            cols = slice(px, px + values.shape[1])
            region = void[a - y0:b - y0, cols]
            if not region.any():
                continue
            lab = self._texel_labels(np.arange(a, b)[:, None], np.arange(px, px + values.shape[1])[None, :]) == k
            take = region & lab
            out[a - y0:b - y0, cols][take] = values[a - py:b - py][take]
        return out

    def points(self, ys, xs):
        out = self.raw.points(ys, xs).astype(np.float32, copy=True)
        void = np.isnan(out)
        if void.any():
            vy, vx = ys[void], xs[void]
            lab = self._texel_labels(vy, vx)
            got = np.empty(vy.shape, np.float32)
            for k in np.unique(lab):
                py, px, values = self.patches[int(k) - 1]
                sel = lab == k
                got[sel] = values[vy[sel] - py, vx[sel] - px]
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


def name_size(w, h):
    """``"W x H samples"`` for messages."""
    return f"{w:,} x {h:,} samples"

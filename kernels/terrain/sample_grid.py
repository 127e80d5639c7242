"""Height samples that are never held whole: TIFF images read block by block, several files on one grid.

A `SampleGrid` answers the two questions the terrain asks of its samples: a window of rows and columns (the
analysis, the GPU preview; a farm task reads only its block's) and the values at scattered points (the mesh). Rows
count from the bottom (row 0 is the southern edge, Blender's image order); files store their top row first.

`TiffSource` decodes one TIFF's samples through OpenImageIO (every compression and predictor its libtiff
reads) a block at a time (whole tiles of a tiled file, whole-width strips of a striped one), keeping the last few
blocks; `Mosaic` lays several
sources on one grid by their sample offsets (a DEM split over adjacent files), where a sample no file covers is a
void. Values are float32; voids (no file, the file's no-data value, NaN) are NaN here, and the layer above
(`void_fill.FilledGrid`) fills or cuts them before any height reaches the terrain.
"""

import math
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np

from ..common.errors import InvalidInputError, TesseraError
from ..common.image_io import oiio_module

#: Bytes of decoded blocks a source keeps (at least two blocks are kept whatever their size).
CACHE_BYTES = 64 * 2**20
#: Rows per block of a striped file (tiled files use whole tile rows, at least this many rows).
BLOCK_ROWS = 256
#: Columns per block of a tiled file (whole tiles, at least this many columns); striped files decode whole rows.
BLOCK_COLS = 256
#: Sample formats read exactly as float32.
_EXACT = {"int8", "uint8", "int16", "uint16", "half", "float"}
_NUMERIC = _EXACT | {"int32", "uint32", "double"}


class SampleGrid:
    """Read-only (H, W) float32 samples, row 0 at the bottom, answering ``grid[y0:y1]`` (a band of rows,
    (y1 - y0, W)), ``grid[y0:y1, x0:x1]`` (a window, (y1 - y0, x1 - x0)) and ``grid[ys, xs]`` (int arrays of equal
    shape -> values of that shape)."""

    ndim = 2
    dtype = np.dtype(np.float32)
    shape = (0, 0)

    def window(self, y0, y1, x0, x1):  # pragma: no cover - the interface
        """Rows ``[y0, y1)`` (from the bottom), columns ``[x0, x1)``: (y1 - y0, x1 - x0) float32."""
        raise NotImplementedError

    def points(self, ys, xs):  # pragma: no cover - the interface
        raise NotImplementedError

    def band(self, y0, y1):
        """Whole rows ``[y0, y1)``: (y1 - y0, W) float32."""
        return self.window(y0, y1, 0, self.shape[1])

    def __len__(self):
        return self.shape[0]

    def __getitem__(self, key):
        if isinstance(key, slice):
            key = (key, slice(None))
        if isinstance(key, tuple) and len(key) == 2 and all(isinstance(k, slice) for k in key):
            (y0, y1, sy), (x0, x1, sx) = (k.indices(n) for k, n in zip(key, self.shape, strict=True))
            if sy != 1 or sx != 1:
                raise IndexError("sample grids give windows of consecutive rows and columns")
            return self.window(y0, max(y0, y1), x0, max(x0, x1))
        if isinstance(key, tuple) and len(key) == 2:
            ys, xs = np.broadcast_arrays(np.asarray(key[0], np.int64), np.asarray(key[1], np.int64))
            return self.points(ys, xs)
        raise IndexError(f"sample grids take row and column slices or two index arrays, not {key!r}")


class HeldWindow(SampleGrid):
    """``grid``'s samples with one window, rows ``[y0, y1)`` and columns ``[x0, x1)`` (from the bottom), read once and
    held in memory: a farm task's region, which its analysis, levels and mesh each read again (a file's blocks are
    then decoded once, not once per pass). Reads outside the window go to ``grid``."""

    def __init__(self, grid, y0, y1, x0, x1):
        self.grid, self.shape, self.box = grid, grid.shape, (y0, y1, x0, x1)
        self.data = grid.window(y0, y1, x0, x1)

    def window(self, y0, y1, x0, x1):
        a, b, c, d = self.box
        if a <= y0 and y1 <= b and c <= x0 and x1 <= d:
            return self.data[y0 - a:y1 - a, x0 - c:x1 - c].copy()
        return self.grid.window(y0, y1, x0, x1)

    def points(self, ys, xs):
        a, b, c, d = self.box
        inside = (ys >= a) & (ys < b) & (xs >= c) & (xs < d)
        out = np.empty(ys.shape, np.float32)
        out[inside] = self.data[ys[inside] - a, xs[inside] - c]
        if not inside.all():
            out[~inside] = self.grid.points(ys[~inside], xs[~inside])
        return out


@dataclass(frozen=True)
class TiffLayout:
    """What a TIFF's header says about its samples: width, height, channels, format name (OpenImageIO's),
    block rows (whole tile rows or strips) and columns (whole tiles, or the width), and whether it is tiled."""

    width: int
    height: int
    channels: int
    format: str
    block_rows: int
    tiled: bool
    block_cols: int = 0


def tiff_layout(path):
    """The `TiffLayout` of ``path``'s first image, from its header; refuses non-numeric samples."""
    oiio = oiio_module()
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise InvalidInputError(f"Cannot read {path}: {(oiio.geterror() or 'not a TIFF file').strip()}")
    try:
        spec = inp.spec()
        fmt = str(spec.format)
        tile = int(spec.tile_height) if spec.tile_width else 0
        tile_w = int(spec.tile_width)
    finally:
        inp.close()
    if fmt not in _NUMERIC:
        raise InvalidInputError(f"{path} stores {fmt} samples; elevation data must be integers or floats")
    rows, cols = block_shape((tile, tile_w) if tile else None, int(spec.width), int(spec.height))
    return TiffLayout(int(spec.width), int(spec.height), int(spec.nchannels), fmt, rows, bool(tile), cols)


def block_shape(tile, width, height):
    """Rows and columns of the blocks read from a ``width`` x ``height`` file stored in ``tile`` = (rows, columns)
    blocks (strips: as wide as the file; None: unknown strips): whole tiles, at least `BLOCK_ROWS` x `BLOCK_COLS`;
    strips in `BLOCK_ROWS` (or whole strips) of the whole width, since a strip is decoded whole."""
    rows, cols = tile or (0, width)
    rows = rows * max(1, -(-BLOCK_ROWS // rows)) if 1 < rows < height else BLOCK_ROWS
    return rows, width if cols >= width else min(width, cols * max(1, -(-BLOCK_COLS // cols)))


def nodata_mask(raw, nodata):
    """Where ``raw`` (the file's stored type) equals the no-data value as that type holds it: (H, W) bool. A float's
    value is compared in the file's float type (the lowest float32, as GDAL writes it, included), an integer's as
    stored; a value the type cannot hold marks nothing (GDAL does the same); NaN marks the NaN samples."""
    if nodata is None:
        return np.zeros(raw.shape, bool)
    if math.isnan(nodata):
        return np.isnan(raw) if raw.dtype.kind == "f" else np.zeros(raw.shape, bool)
    if raw.dtype.kind == "f":
        with np.errstate(over="ignore"):
            return raw == raw.dtype.type(nodata)
    info = np.iinfo(raw.dtype)
    if not (float(nodata).is_integer() and info.min <= nodata <= info.max):
        return np.zeros(raw.shape, bool)
    return raw == raw.dtype.type(int(nodata))


class BlockSource:
    """One file's samples decoded a block at a time (file order: row 0 at the top): blocks of ``block_rows`` rows and
    ``block_cols`` columns (0: the whole width), the last few kept (`CACHE_BYTES`), so a window reads only the blocks
    it covers. A subclass sets ``shape`` (H, W), the block shape, ``nodata`` (None: none), ``scale`` and ``offset``
    (a sample means ``offset + scale * stored``) and decodes one block (`_decode`, through `_heights`)."""

    shape = (0, 0)
    block_rows = BLOCK_ROWS
    block_cols = 0
    nodata = None
    scale, offset = 1.0, 0.0

    def _heights(self, raw, void=None):
        """Stored samples ``raw`` (the file's type, a fresh array) as float32 heights after the scale and offset;
        voids NaN: ``void`` (bool, e.g. a mask band), the no-data value compared as stored, values not finite."""
        if self.scale != 1.0 or self.offset != 0.0:
            out = (raw.astype(np.float64) * self.scale + self.offset).astype(np.float32)
        else:
            out = raw.astype(np.float32, copy=False)
        bad = ~np.isfinite(out)  # NaN no-data included
        if self.nodata is not None and not math.isnan(self.nodata):
            bad |= nodata_mask(raw, self.nodata)
        if void is not None:
            bad |= void
        out[bad] = np.nan
        return out

    @property
    def _cols(self):
        return self.block_cols or self.shape[1]

    def _init_cache(self, cache_bytes):
        # (block row, block column) -> (the decoded span holding it: (rows, columns) float32, the span's first block
        # column): blocks decoded together stay one array, so a window across them is a slice, not a copy
        self._cache = OrderedDict()
        self._keep = max(2, cache_bytes // max(1, self.block_rows * self._cols * 4))

    def _decode(self, r0, r1, c0, c1):  # pragma: no cover - the interface
        """File rows ``[r0, r1)``, columns ``[c0, c1)`` (one block): float32 heights, voids NaN."""
        raise NotImplementedError

    def block(self, bi, bj=0):
        """Decoded block ``(bi, bj)`` (block row, block column): (rows, columns) float32 (file order), voids NaN."""
        span, first = self._span(bi, bj)
        c = self._cols
        return span[:, (bj - first) * c:(bj - first + 1) * c]

    def _span(self, bi, bj):
        """The decoded span holding block ``(bi, bj)`` and the span's first block column (decoded if not kept)."""
        key = (bi, bj)
        hit = self._cache.get(key)
        if hit is None:
            self._load(bi, bj, bj)
            hit = self._cache[key]
        self._cache.move_to_end(key)
        return hit

    def _load(self, bi, j0, j1):
        """Decode blocks ``(bi, j0) .. (bi, j1)`` of one block row in one read (a file's reader pays per call) and keep
        them."""
        (h, w), b, c = self.shape, self.block_rows, self._cols
        data = self._decode(bi * b, min(h, (bi + 1) * b), j0 * c, min(w, (j1 + 1) * c))
        data.flags.writeable = False  # windows are slices of it: a reader that writes must copy
        for bj in range(j0, j1 + 1):
            self._cache[(bi, bj)] = (data, j0)
            self._cache.move_to_end((bi, bj))
        while len(self._cache) > self._keep:
            self._cache.popitem(last=False)

    def _prefetch(self, bi, columns):
        """Decode the blocks of block row ``bi`` among block columns ``columns`` (sorted ints) that are not kept,
        several in one read: from the first missing to the last (at most the cache's size)."""
        missing = [bj for bj in columns if (bi, bj) not in self._cache]
        if len(missing) > 1 and missing[-1] - missing[0] < self._keep:
            self._load(bi, missing[0], missing[-1])

    def window(self, r0, r1, c0, c1):
        """File rows ``[r0, r1)``, columns ``[c0, c1)``: (r1 - r0, c1 - c0) float32, voids NaN; only the blocks the
        window covers are decoded."""
        b, c = self.block_rows, self._cols
        if r1 <= r0 or c1 <= c0:
            return np.empty((max(0, r1 - r0), max(0, c1 - c0)), np.float32)
        bands = []
        for bi in range(r0 // b, (r1 - 1) // b + 1):
            lo = bi * b
            rs = slice(max(r0, lo) - lo, min(r1, lo + b) - lo)
            j0, j1 = c0 // c, (c1 - 1) // c
            self._prefetch(bi, range(j0, j1 + 1))
            spans = [self._span(bi, bj) for bj in range(j0, j1 + 1)]
            span, first = spans[0]
            if all(s is span for s, _ in spans):  # one decoded span: a slice of it
                bands.append(span[rs, c0 - first * c:c1 - first * c])
                continue
            parts = []
            for bj, (span, first) in zip(range(j0, j1 + 1), spans, strict=True):
                left = bj * c
                parts.append(span[rs, max(c0, left) - first * c:min(c1, left + c) - first * c])
            bands.append(np.concatenate(parts, axis=1))
        return bands[0] if len(bands) == 1 else np.concatenate(bands)

    def rows(self, r0, r1):
        """File rows ``[r0, r1)``: (r1 - r0, W) float32, voids NaN."""
        return self.window(r0, r1, 0, self.shape[1])

    def points(self, rows, cols):
        """Values at file rows and columns (int64 (n,) each, inside the image): (n,) float32."""
        out = np.empty(rows.shape, np.float32)
        bi, bj = rows // self.block_rows, cols // self._cols
        key = bi * (self.shape[1] // self._cols + 1) + bj
        order = np.argsort(key, kind="stable")
        edges = np.flatnonzero(np.diff(key[order])) + 1
        row, in_rows = None, bi[order]
        for run in np.split(order, edges):  # block by block, block rows in order
            if run.size:
                i, j = int(bi[run[0]]), int(bj[run[0]])
                if i != row and self._cols < self.shape[1]:  # the row's blocks asked for, in one read
                    row = i
                    lo, hi = np.searchsorted(in_rows, [i, i + 1])
                    self._prefetch(i, np.unique(bj[order[lo:hi]]).tolist())
                out[run] = self.block(i, j)[rows[run] - i * self.block_rows, cols[run] - j * self._cols]
        return out


class TiffSource(BlockSource):
    """One TIFF image's first channel, decoded through OpenImageIO a block of rows at a time (`BlockSource`).

    ``nodata``: the file's no-data value (None: none); its samples, and NaN, read as NaN. ``scale``, ``offset``:
    a sample means ``offset + scale * stored`` (GDAL's band scale and offset).
    """

    def __init__(self, path, layout, nodata=None, scale=1.0, offset=0.0):
        self.path, self.layout, self.nodata = path, layout, nodata
        self.scale, self.offset = float(scale), float(offset)
        self.shape, self.block_rows = (layout.height, layout.width), layout.block_rows
        self.block_cols = layout.block_cols if layout.tiled else 0
        self._init_cache(CACHE_BYTES)

    def _decode(self, r0, r1, c0, c1):
        lay = self.layout
        oiio = oiio_module()
        inp = oiio.ImageInput.open(self.path)
        if inp is None:
            raise TesseraError(f"Cannot read {self.path}: {(oiio.geterror() or 'the file is gone').strip()}")
        try:
            # "unknown": the file's own type (OpenImageIO would scale integers into [0, 1] for "float")
            if lay.tiled:  # whole tiles: the block's columns start and end on tile borders (or the image's edge)
                data = inp.read_tiles(0, 0, c0, c1, r0, r1, 0, 1, 0, 1, "unknown")
            else:  # a strip is decoded whole
                data = inp.read_scanlines(0, 0, r0, r1, 0, 0, 1, "unknown")
            error = inp.geterror()  # a strip it cannot decode still returns an array, with an error set
            if data is None or error:
                reason = (error or oiio.geterror() or "the file is damaged or truncated").strip()
                raise InvalidInputError(f"Reading rows {r0}-{r1 - 1} of {self.path} failed: {reason}")
        finally:
            inp.close()
        return self._heights(np.asarray(data).reshape(r1 - r0, c1 - c0))  # strips: the whole width


class Mosaic(SampleGrid):
    """Sources placed on one grid: ``placements`` is a list of (source, column offset, row offset from the top);
    the grid spans them all. Where sources overlap, the first in the list gives the sample. Row 0 at the bottom."""

    def __init__(self, placements, width, height):
        self.placements = list(placements)
        self.shape = (int(height), int(width))

    def window(self, y0, y1, x0, x1):
        h = self.shape[0]
        out = np.full((y1 - y0, x1 - x0), np.nan, np.float32)
        if y1 <= y0 or x1 <= x0:
            return out
        filled = np.zeros(out.shape, bool) if len(self.placements) > 1 else None
        top0, top1 = h - y1, h - y0  # the window in top-first rows [top0, top1)
        for source, col, row in self.placements:
            sh, sw = source.shape
            a, b = max(top0, row), min(top1, row + sh)
            left, right = max(x0, col), min(x1, col + sw)
            if a >= b or left >= right:
                continue
            rows = source.window(a - row, b - row, left - col, right - col)[::-1]  # bottom-first
            sl = (slice(top1 - b, top1 - a), slice(left - x0, right - x0))
            if filled is None:
                out[sl] = rows
            else:
                take = ~filled[sl]
                out[sl][take] = rows[take]
                filled[sl] = True
        return out

    def points(self, ys, xs):
        h = self.shape[0]
        top = (h - 1 - ys).ravel()
        x = xs.ravel()
        out = np.full(top.shape, np.nan, np.float32)
        todo = np.ones(top.shape, bool)
        for source, col, row in self.placements:
            sh, sw = source.shape
            inside = todo & (top >= row) & (top < row + sh) & (x >= col) & (x < col + sw)
            if inside.any():
                out[inside] = source.points(top[inside] - row, x[inside] - col)
                todo &= ~inside
        return out.reshape(ys.shape)

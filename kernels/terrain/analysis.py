"""Height-map analysis ([Nunes 2011, §5.4], §5.6): the height acceleration map (HAM) and the per-tile table.

    M   = |Sobel(H)|     D_x = [-1 -2 -1; 0 0 0; 1 2 1] * H,  D_y = its transpose,  |D| = sqrt(D_x² + D_y²)
    HAM = |Sobel(M)|

with clamp-to-edge borders at every pass. H is taken in texel units (world height / texel size), so the HAM
of a terrain does not change when the whole terrain is scaled: a ramp of slope s gives M = 8 s, and the HAM
measures how fast that slope changes (64 × the change of slope per texel, on a crease).

Tiles split the sample grid into squares of ``tile_size`` intervals; tile (ty, tx) covers the samples
``x in [tx·ts, min((tx+1)·ts, W-1)]`` and the same for y (both ends included: neighbours share a row). The
tile table holds, per tile, the HAM maximum, the height range and the position of the highest sample (the
first in row-major order among equals), [Nunes 2011]'s RGBA tile texture plus ``h_min`` for culling.

Integer elevation data (whole metres, decimetres) is stored in steps of a quantum q: its rounding error is at most q
in range, which |Sobel| turns into at most 4·sqrt(2)·q of slope and, through the second pass, at most 64·q of HAM
(texel units). Terraces that rounding made can therefore never raise the HAM by more than 64·q, and the tile table
discounts exactly that (`quantisation_floor`): a whole-metre DEM of a smooth slope is as smooth as the same slope
stored as float, never rougher. The mesh keeps the file's values at its samples.

Everything runs on bands of tile rows, so a memory-mapped map of any size is analysed with memory bounded
by a few bands (`tile_table`), and an edit re-analyses only the tiles it can reach (`update_tiles`).
"""

from dataclasses import dataclass, field

import numpy as np

from ..common.errors import InvalidInputError
from ..common.opencl_runtime import backend_runtime

#: HAM rows at the border of an edit that change: the two Sobel passes each reach one sample.
HAM_REACH = 2
#: The most HAM (texel units) a rounding error of one quantum can make: |Sobel| of an error within [0, q] is at most
#: 4·sqrt(2)·q, and |Sobel| of an error within a range of 8·sqrt(2)·q at most 4·sqrt(2)·8·sqrt(2)·q = 64·q.
HAM_PER_QUANTUM = 64.0
#: A map read from disk (memory-mapped, or block by block) goes to the device whole only up to this many bytes of
#: float32; larger ones stay in bands on the host, so the analysis of any size keeps its memory bound.
OUT_OF_CORE_DEVICE_BYTES = 64 * 2**20


def tile_counts(width, height, tile_size):
    """Tiles across and down for a ``width`` × ``height`` sample grid: (ntx, nty)."""
    if int(tile_size) != tile_size or tile_size < 1:
        raise InvalidInputError(f"The tile size must be a positive whole number of texels; got {tile_size!r}")
    return -(-(width - 1) // tile_size), -(-(height - 1) // tile_size)


def tile_bounds(index, tile_size, samples):
    """First and last sample (inclusive) of tiles ``index`` along one axis: two int64 arrays."""
    i = np.asarray(index, np.int64)
    return i * tile_size, np.minimum((i + 1) * tile_size, samples - 1)


def sobel_magnitude(rows):
    """|Sobel| of the middle rows: rows (n + 2, W) float32 with one halo row each side -> (n, W) float32.

    Columns are clamped at the left and right edges; the caller supplies the halo rows (clamped or real).
    """
    p = np.pad(np.asarray(rows, np.float32), ((0, 0), (1, 1)), mode="edge")
    top = p[:-2, :-2] + 2 * p[:-2, 1:-1] + p[:-2, 2:]
    bottom = p[2:, :-2] + 2 * p[2:, 1:-1] + p[2:, 2:]
    left = p[:-2, :-2] + 2 * p[1:-1, :-2] + p[2:, :-2]
    right = p[:-2, 2:] + 2 * p[1:-1, 2:] + p[2:, 2:]
    gx, gy = bottom - top, right - left
    return np.sqrt(gx * gx + gy * gy)


def ham_rows(get_rows, n_rows, y0, y1):
    """HAM rows ``[y0, y1]`` (inclusive) of a map with ``n_rows`` rows: (y1 - y0 + 1, W) float32.

    ``get_rows(index)`` returns the heights (texel units, float32) of the given row indices; only rows
    ``y0 - 2 .. y1 + 2`` (clamped) are asked for.
    """
    m_lo, m_hi = max(0, y0 - 1), min(n_rows - 1, y1 + 1)
    h = get_rows(np.clip(np.arange(m_lo - 1, m_hi + 2), 0, n_rows - 1))
    m = sobel_magnitude(h)
    return sobel_magnitude(m[np.clip(np.arange(y0 - 1, y1 + 2), m_lo, m_hi) - m_lo])


def ham(heights):
    """The height acceleration map of (H, W) heights in texel units: (H, W) float32."""
    h = np.asarray(heights, np.float32)
    if h.ndim != 2 or min(h.shape) < 2:
        raise InvalidInputError("The terrain analysis needs a 2-D height array of at least 2x2 samples")
    return ham_rows(lambda idx: h[idx], h.shape[0], 0, h.shape[0] - 1)


@dataclass
class TileTable:
    """Per-tile analysis, all (nty, ntx): ham_max, h_min, h_max float32 (world heights); peak_x, peak_y int32
    (sample coordinates of the highest sample). ``tile_size`` in texel intervals; ``shape`` = (H, W) samples."""

    tile_size: int
    shape: tuple
    ham_max: np.ndarray
    h_min: np.ndarray
    h_max: np.ndarray
    peak_x: np.ndarray
    peak_y: np.ndarray
    #: camera-independent values derived from the table (level selection fills it; edits clear it)
    derived: dict = field(default_factory=dict, repr=False, compare=False)

    @classmethod
    def empty(cls, shape, tile_size):
        ntx, nty = tile_counts(shape[1], shape[0], tile_size)
        f = [np.zeros((nty, ntx), np.float32) for _ in range(3)]
        i = [np.zeros((nty, ntx), np.int32) for _ in range(2)]
        return cls(int(tile_size), tuple(shape), *f, *i)

    @property
    def counts(self):
        """(ntx, nty)."""
        return self.ham_max.shape[1], self.ham_max.shape[0]

    def rgba(self):
        """[Nunes 2011]'s tile texture: (nty, ntx, 4) float32 = (HAM_max, h_max, x of h_max, y of h_max)."""
        return np.stack([self.ham_max, self.h_max, self.peak_x.astype(np.float32),
                         self.peak_y.astype(np.float32)], axis=-1)


def _windows(band, tile_size, count, fill):
    """The first ``count`` tile windows of a band of rows: (count, rows, tile_size + 1) view (padded with
    ``fill`` past the band's last column)."""
    need = count * tile_size + 1
    cols = band[:, :need]
    if cols.shape[1] < need:
        cols = np.pad(cols, ((0, 0), (0, need - cols.shape[1])), constant_values=fill)
    cols = np.ascontiguousarray(cols)
    s0, s1 = cols.strides
    return np.lib.stride_tricks.as_strided(cols, (count, cols.shape[0], tile_size + 1),
                                           (s1 * tile_size, s0, s1), writeable=False)


def _analyse(table, hm, ty0, ty1, tx0, tx1, progress=None):
    """Fill tiles rows ``[ty0, ty1)``, columns ``[tx0, tx1)`` of ``table`` from height map ``hm``, reading only those
    tiles' samples and their HAM halo (`HAM_REACH` samples each side)."""
    ts, (n_rows, width) = table.tile_size, table.shape
    inv_texel = np.float32(1.0 / hm.mean_texel)
    c0, c1 = tx0 * ts, min(width, tx1 * ts + 1)
    # the halo columns make the HAM of columns [c0, c1) exact: the Sobel passes clamp at the window's edges, which
    # changes only the HAM_REACH columns next to an edge that is not the map's own
    w0, w1 = max(0, c0 - HAM_REACH), min(width, c1 + HAM_REACH)
    for ty in range(ty0, ty1):
        y0, y1 = (int(v) for v in tile_bounds(ty, ts, n_rows))
        lo = max(0, y0 - HAM_REACH)
        rows = hm.window(lo, min(n_rows, y1 + 1 + HAM_REACH), w0, w1)  # the band and its HAM halo, read once
        band = ham_rows(lambda idx, rows=rows, lo=lo: rows[idx - lo] * inv_texel, n_rows, y0, y1)[:, c0 - w0:c1 - w0]
        _fill_row(table, ty, tx0, tx1, band, rows[y0 - lo:y1 + 1 - lo, c0 - w0:c1 - w0], y0)
        if progress is not None:
            progress(ty - ty0 + 1, ty1 - ty0)


def _fill_row(table, ty, tx0, tx1, ham_band, h_band, y0):
    """Tile statistics of one tile row from bands that start at column ``tx0 · tile_size``."""
    ts = table.tile_size
    sl = (ty, slice(tx0, tx1))
    table.ham_max[sl] = _windows(ham_band, ts, tx1 - tx0, -np.inf).max(axis=(1, 2))
    table.h_min[sl] = _windows(h_band, ts, tx1 - tx0, np.inf).min(axis=(1, 2))
    win = _windows(h_band, ts, tx1 - tx0, -np.inf)
    flat = win.reshape(win.shape[0], -1)
    arg = flat.argmax(axis=1)
    table.h_max[sl] = flat[np.arange(flat.shape[0]), arg]
    table.peak_y[sl] = y0 + arg // (ts + 1)
    table.peak_x[sl] = np.arange(tx0, tx1) * ts + arg % (ts + 1)


def quantisation_floor(hm):
    """The HAM (texel units) that rounding to ``hm.quantum`` can make on its own: float (0 for continuous data)."""
    return HAM_PER_QUANTUM * float(hm.quantum) / hm.mean_texel


def _discount(table, hm, sl=(slice(None), slice(None))):
    """Take the quantisation floor off tiles ``sl``'s HAM maxima (max(HAM - f) = max(HAM) - f, so per tile)."""
    floor = quantisation_floor(hm)
    if floor > 0:
        table.ham_max[sl] = np.maximum(table.ham_max[sl] - np.float32(floor), 0)


def tile_table(hm, tile_size=64, backend="auto", progress=None, tiles=None):
    """Analyse a `heightmap_io.HeightMap` into a `TileTable`.

    numpy works band by band (one tile row at a time, bounded memory: memory-mapped maps of any size);
    OpenCL (``backend="opencl"`` or "auto" with a device) analyses the whole map on the device when it fits
    in memory as float32 (a map read from disk only up to `OUT_OF_CORE_DEVICE_BYTES`). ``progress(done, total)``
    is called after each band. ``tiles`` = (tx0, ty0, tx1, ty1) (end exclusive) analyses only those tiles (numpy,
    reading only their samples: one farm task's block and its ring, `lod.block_region`); the others stay zero. The
    same float32 operations in the same order on either backend: every analysed tile is the whole map's, bit for bit.
    """
    table = TileTable.empty((hm.height, hm.width), tile_size)
    ntx, nty = table.counts
    if tiles is not None and tuple(tiles) != (0, 0, ntx, nty):
        tx0, ty0, tx1, ty1 = (int(v) for v in tiles)
        if not (0 <= tx0 < tx1 <= ntx and 0 <= ty0 < ty1 <= nty):
            raise InvalidInputError(f"Tiles {tuple(tiles)} are not inside the {ntx} x {nty} tiles of the map")
        _analyse(table, hm, ty0, ty1, tx0, tx1, progress)
        _discount(table, hm, (slice(ty0, ty1), slice(tx0, tx1)))
        return table
    runtime = backend_runtime(backend, "the terrain analysis")
    if runtime is not None and _fits_device(runtime, hm):
        from .opencl_path import analyse_on_device

        analyse_on_device(runtime, hm, table)
        _discount(table, hm)
        if progress is not None:
            progress(nty, nty)
        return table
    _analyse(table, hm, 0, nty, 0, ntx, progress)
    _discount(table, hm)
    return table


def _fits_device(runtime, hm):
    need = hm.width * hm.height * 4 * 3  # heights, M, HAM as float32
    if not hm.in_memory and need > 3 * OUT_OF_CORE_DEVICE_BYTES:
        return False
    return need <= min(runtime.device.max_mem_alloc_size * 3, runtime.device.global_mem_size // 2)


def update_tiles(table, hm, region):
    """Re-analyse the tiles an edit of samples ``region = (x0, y0, x1, y1)`` (end exclusive) can change.

    HAM values change up to `HAM_REACH` samples outside the edit, so the tiles touching the grown region are
    recomputed (band by band, numpy). Returns the recomputed tile range ``(tx0, ty0, tx1, ty1)``.
    """
    x0, y0, x1, y1 = (int(v) for v in region)
    ts, (n_rows, width) = table.tile_size, table.shape
    if not (0 <= x0 < x1 <= width and 0 <= y0 < y1 <= n_rows):
        raise InvalidInputError(f"The edited region {region} is not inside the {width}x{n_rows} map")
    ntx, nty = table.counts
    gx0, gy0 = max(0, x0 - HAM_REACH), max(0, y0 - HAM_REACH)
    gx1, gy1 = min(width - 1, x1 - 1 + HAM_REACH), min(n_rows - 1, y1 - 1 + HAM_REACH)
    # a sample on a tile border belongs to both tiles: (g - 1) // ts catches the tile on the low side
    tx0, ty0 = max(0, (gx0 - 1) // ts), max(0, (gy0 - 1) // ts)
    tx1, ty1 = min(ntx, gx1 // ts + 1), min(nty, gy1 // ts + 1)
    _analyse(table, hm, ty0, ty1, tx0, tx1)
    _discount(table, hm, (slice(ty0, ty1), slice(tx0, tx1)))
    table.derived.clear()
    return tx0, ty0, tx1, ty1

"""Height maps in: 8/16-bit PNG/TIFF, float EXR/TIFF (OpenImageIO), raw r16/r32 (memory-mapped), arrays.

A `HeightMap` keeps the samples in the file's own type, so nothing is lost on the way in: 8-bit stays
``uint8``, 16-bit stays ``uint16``, float stays ``float32``. A sample ``s`` means the world height

    z = offset + scale * n(s),   n(s) = s / 255 (8-bit), s / 65535 (16-bit), s (float)

Samples sit on the vertices of a regular grid, ``texel_size`` world units apart; row 0 is the bottom row
(Blender's image order, v = 0). Image files store their top row first and are flipped (a view, no copy);
raw files are taken as top row first too (the common r16/r32 layout) unless ``raw_bottom_up``.

Raw files are memory-mapped, never read whole: a 65536² r16 file (8 GiB) costs no memory until its rows are
touched, and `rows` converts only the band asked for.
"""

import os
from dataclasses import dataclass

import numpy as np

from ..common.budget import check_bytes
from ..common.errors import BudgetError, InvalidInputError, TesseraError
from ..common.image_io import read_pixels
from ..common.limits import MAX_WORLD_VALUE
from .sample_grid import SampleGrid

IMAGE_EXTENSIONS = (".png", ".tif", ".tiff", ".exr")
RAW_TYPES = {".r16": np.dtype("<u2"), ".raw": np.dtype("<u2"), ".r32": np.dtype("<f4")}
_NORMALISE = {np.dtype(np.uint8): 1.0 / 255.0, np.dtype(np.uint16): 1.0 / 65535.0}
#: Rows per band when a large map is scanned (NaN check, statistics): about 64 MiB of float32 at 16384 wide.
SCAN_ROWS = 1024


@dataclass(frozen=True)
class HeightMap:
    """Height samples and their world scale.

    samples: (H, W) uint8, uint16 or float32 (may be a read-only memory map, or a `sample_grid.SampleGrid` read
    block by block: a GeoTIFF, its voids filled); row 0 at the bottom.
    texel_size: world distance between neighbouring samples along x (> 0); texel_size_y: along y (0: the same;
    geographic data has longer rows than columns away from the equator). scale, offset: see the module docstring.
    quantum: the world height between neighbouring values the file could store (an integer DEM's step: 1 m for
    whole metres), 0 for continuous data; the roughness analysis discounts what that rounding can fake
    (`analysis.quantisation_floor`).
    """

    samples: np.ndarray
    texel_size: float = 1.0
    scale: float = 1.0
    offset: float = 0.0
    source: str = ""
    texel_size_y: float = 0.0
    quantum: float = 0.0

    def __post_init__(self):
        s = self.samples
        if not isinstance(s, np.ndarray | SampleGrid) or s.ndim != 2 or s.dtype not in (np.uint8, np.uint16,
                                                                                        np.float32):
            raise InvalidInputError("Height samples must be a 2-D uint8, uint16 or float32 array")
        if min(s.shape) < 2:
            raise InvalidInputError(f"A height map needs at least 2x2 samples; got {s.shape[1]}x{s.shape[0]}")
        for name, label in (("texel_size", "Texel Size"), ("texel_size_y", "Texel Size Y"),
                            ("scale", "Height Scale"), ("offset", "Height Offset")):
            value = getattr(self, name)
            if not (np.isfinite(value) and abs(value) <= MAX_WORLD_VALUE):
                raise InvalidInputError(f"{label} must be a finite number between {-MAX_WORLD_VALUE:g} and "
                                        f"{MAX_WORLD_VALUE:g}; got {value!r}")
        if not (np.isfinite(self.quantum) and 0 <= self.quantum <= MAX_WORLD_VALUE):
            raise InvalidInputError(f"The height step must be a finite number >= 0; got {self.quantum!r}")
        if not (self.texel_size > 0 and self.texel_size_y >= 0):
            raise InvalidInputError(f"The texel size must be positive; got {self.texel_size!r}")

    @property
    def texel(self):
        """World distance between samples along x and y: (tx, ty)."""
        return self.texel_size, self.texel_size_y or self.texel_size

    @property
    def mean_texel(self):
        """The geometric mean of the two spacings: the one length the height analysis measures slopes in."""
        tx, ty = self.texel
        return tx if tx == ty else float(np.sqrt(tx * ty))

    @property
    def in_memory(self):
        """Whether every sample is held in memory (not a memory map, not a grid read block by block)."""
        return isinstance(self.samples, np.ndarray) and not isinstance(self.samples, np.memmap)

    def hold(self, window, budget_bytes=0):
        """Keep the samples of ``window`` = (y0, y1, x0, x1) (rows and columns from the bottom, end exclusive) in memory
        when they are read from a file (a farm task's region: `lod.block_window`), if they fit ``budget_bytes`` (0: no
        budget) and the memory free; otherwise (and for maps in memory or memory-mapped) nothing changes. Returns
        whether they are held."""
        hold = getattr(self.samples, "hold", None)
        if hold is None:
            return False
        y0, y1, x0, x1 = window
        try:
            check_bytes((y1 - y0) * (x1 - x0) * 4, budget_bytes, "", "")
        except BudgetError:
            return False  # read as it goes: more decoding, the same values
        hold(y0, y1, x0, x1)
        return True

    def void_at(self, x, y):
        """Whether points at sample coordinates ``x, y`` touch a void that is cut out (a hole): bool array, or
        None when the map has no holes."""
        cut = getattr(self.samples, "void_at", None)
        return None if cut is None or not getattr(self.samples, "cut", False) else cut(x, y)

    @property
    def width(self):
        return self.samples.shape[1]

    @property
    def height(self):
        return self.samples.shape[0]

    @property
    def unit(self):
        """World height of one stored unit: (scale / 255, scale / 65535 or scale)."""
        return self.scale * _NORMALISE.get(self.samples.dtype, 1.0)

    def rows(self, y0, y1):
        """World heights of rows ``[y0, y1)``: (y1 - y0, W) float32 (a copy; the samples are untouched)."""
        return self.window(y0, y1, 0, self.width)

    def window(self, y0, y1, x0, x1):
        """World heights of rows ``[y0, y1)``, columns ``[x0, x1)``: (y1 - y0, x1 - x0) float32 (a copy); a map read
        from a file reads only the blocks the window covers."""
        band = np.asarray(self.samples[y0:y1, x0:x1], np.float32)
        return (np.float32(self.offset) + np.float32(self.unit) * band).astype(np.float32)

    def heights(self):
        """All world heights: (H, W) float32. Use `rows` for maps too large to hold as float32."""
        return self.rows(0, self.height)

    def sample(self, x, y):
        """Bilinear world height at texel coordinates (clamped to the map): x, y (...) float -> (...) float32.

        Only the four neighbours of each point are read, so this works on memory-mapped maps.
        """
        x = np.clip(np.asarray(x, np.float64), 0.0, self.width - 1)
        y = np.clip(np.asarray(y, np.float64), 0.0, self.height - 1)
        x0 = np.minimum(np.floor(x).astype(np.int64), self.width - 2)
        y0 = np.minimum(np.floor(y).astype(np.int64), self.height - 2)
        fx, fy = x - x0, y - y0
        # the four neighbours in one read: a grid read from a file decodes each of its blocks once, not four times
        ys = np.concatenate([y0.ravel(), y0.ravel(), y0.ravel() + 1, y0.ravel() + 1])
        xs = np.concatenate([x0.ravel(), x0.ravel() + 1, x0.ravel(), x0.ravel() + 1])
        h00, h10, h01, h11 = (h.reshape(x0.shape) for h in np.split(self.samples[ys, xs].astype(np.float64), 4))
        n = (h00 * (1 - fx) + h10 * fx) * (1 - fy) + (h01 * (1 - fx) + h11 * fx) * fy
        return (self.offset + self.unit * n).astype(np.float32)


def check_finite(samples, source="", top_first=True):
    """Raise `InvalidInputError` if float samples hold NaN or infinity (scanned in bands).

    samples: (H, W), row 0 at the bottom. The message gives the first bad sample's row and column as the source
    counts them: from the top for files (``top_first``, their order on disk), from the bottom otherwise.
    """
    if samples.dtype.kind != "f":
        return
    h = samples.shape[0]
    for y0 in range(0, h, SCAN_ROWS):
        band = samples[y0:y0 + SCAN_ROWS]
        if not np.isfinite(band).all():
            bad = np.argwhere(~np.isfinite(band))
            rows = y0 + bad[:, 0]
            where = f" in {source}" if source else ""
            if top_first:
                row = int(h - 1 - rows.max())  # the first bad row in the file's own order
                col = int(bad[rows == rows.max()][0, 1])
                raise InvalidInputError(f"The height map{where} has NaN or infinity at row {row} (counted from the "
                                        f"top, as stored), column {col}")
            raise InvalidInputError(f"The height map{where} has NaN or infinity at row {int(rows[0])} (counted "
                                    f"from the bottom), column {int(bad[0, 1])}")


def from_array(samples, texel_size=1.0, scale=1.0, offset=0.0, source="", top_first=False):
    """A `HeightMap` from an (H, W) or (H, W, C) array (channel 0 is used; row 0 at the bottom), checked for NaN;
    ``top_first``: the source stores its top row first (a file), for the rows that messages name."""
    a = np.asarray(samples)
    if a.ndim == 3:
        a = a[..., 0]
    if a.dtype.kind == "f" and a.dtype != np.float32:
        a = a.astype(np.float32)
    check_finite(a, source, top_first)
    return HeightMap(a, float(texel_size), float(scale), float(offset), source)


def read_raw(path, width, height, dtype=None, texel_size=1.0, scale=1.0, offset=0.0, bottom_up=False):
    """Memory-map a raw height file: little-endian uint16 (.r16/.raw) or float32 (.r32), top row first.

    The file size must be exactly ``width * height * itemsize``. Float files are scanned for NaN in bands.
    """
    if not os.path.isfile(path):
        raise TesseraError(f"No such height map file: {path}")
    ext = os.path.splitext(path)[1].lower()
    dt = np.dtype(dtype) if dtype is not None else RAW_TYPES.get(ext)
    if dt is None or dt not in (np.dtype("<u2"), np.dtype("<f4"), np.dtype("u1")):
        raise InvalidInputError(f"Raw height maps are .r16/.raw (uint16) or .r32 (float32); got {path!r}")
    width, height = int(width), int(height)
    if width < 2 or height < 2:
        raise InvalidInputError(f"Give the raw map's size (at least 2x2); got {width}x{height}")
    expected = width * height * dt.itemsize
    actual = os.path.getsize(path)
    if actual != expected:
        side = int(round((actual / dt.itemsize) ** 0.5))
        hint = f"; a square map of this file would be {side}x{side}" if side * side * dt.itemsize == actual else ""
        name = os.path.basename(path)
        raise InvalidInputError(f"{name} has {actual} bytes; {width}x{height} {dt.name} samples need {expected}{hint}")
    mm = np.memmap(path, dtype=dt, mode="r", shape=(height, width))
    samples = mm if bottom_up else mm[::-1]
    check_finite(samples, path, top_first=not bottom_up)
    return HeightMap(samples, float(texel_size), float(scale), float(offset), path)


def read_image(path, texel_size=1.0, scale=1.0, offset=0.0):
    """Read a PNG/TIFF/EXR height map with OpenImageIO, keeping its precision (channel 0 is the height)."""
    def pixel_type(fmt):
        kind = {"uint8": "uint8", "uint16": "uint16", "float": "float", "half": "float", "double": "float"}.get(fmt)
        if kind is None:
            raise InvalidInputError(f"{path} stores {fmt} samples; use 8/16-bit integer or float height maps")
        return kind

    data, _ = read_pixels(path, "height map", pixel_type, n_channels=1)
    return from_array(np.ascontiguousarray(data[..., 0]), texel_size, scale, offset, path, top_first=True)


def _raw_size_hint(path, dtype=None):
    """What to tell a user who gave no size for a raw file: the byte count, and what it allows."""
    name = os.path.basename(path)
    if not os.path.isfile(path):
        return f"No such height map file: {path}"
    dt = np.dtype(dtype) if dtype is not None else RAW_TYPES.get(os.path.splitext(path)[1].lower(), np.dtype("<u2"))
    size = os.path.getsize(path)
    if size % dt.itemsize:
        return (f"{name} is a raw height map of {size} bytes, an odd count: not a whole number of {dt.itemsize}-byte "
                f"{dt.name} samples (is it truncated, or 8-bit?)")
    n = size // dt.itemsize
    side = int(round(n ** 0.5))
    square = f"; as a square it would be {side}x{side}" if side * side == n else ""
    return (f"{name} is a raw height map of {n} {dt.name} samples: give its width and height (Raw Width, "
            f"Raw Height){square}")


def read_heightmap(path, texel_size=1.0, scale=1.0, offset=0.0, raw_size=None, raw_dtype=None, raw_bottom_up=False):
    """Read any supported height map file. ``raw_size=(width, height)`` is required for raw files."""
    ext = os.path.splitext(path)[1].lower()
    if ext in RAW_TYPES or raw_dtype is not None:
        if raw_size is None:
            raise InvalidInputError(_raw_size_hint(path, raw_dtype))
        return read_raw(path, raw_size[0], raw_size[1], raw_dtype, texel_size, scale, offset, raw_bottom_up)
    if ext in IMAGE_EXTENSIONS:
        return read_image(path, texel_size, scale, offset)
    raise InvalidInputError(
        f"Unsupported height map {os.path.basename(path)!r}; use {', '.join(IMAGE_EXTENSIONS + tuple(RAW_TYPES))}")

"""Elevation rasters read through GDAL (the rasterio wheels bundle it): every format and convention GDAL knows.

GeoTIFF with any compression GDAL was built with (deflate, LZW, ZSTD, LERC, JPEG...), BigTIFF, sparse and
cloud-optimised files, SRTM ``.hgt`` tiles, ESRI ASCII grids (``.asc``), ERDAS Imagine (``.img``), virtual mosaics
(``.vrt``) and the rest of GDAL's raster drivers. What is taken from the dataset, never guessed:

- **Placement**: the geotransform, which GDAL already gives for pixel corners whatever the raster type
  (*PixelIsPoint* files are shifted by half a sample on the way in), so a sample's centre is ``T * (col + 0.5,
  row + 0.5)``. A rotated, sheared or south-up raster, or one placed by control points, is warped north up through
  a virtual warp (`rasterio.vrt.WarpedVRT`, bilinear, read a block at a time like the file itself) and the note
  says so.
- **Units**: horizontal from the CRS as PROJ resolves it (EPSG codes included: a compound EPSG:2227+6360 is in US
  survey feet), vertical from the band's unit or the CRS's vertical part; metres where neither says (noted).
- **Voids**: the band's no-data value compared in the band's own type (the lowest float32 included), its mask band
  (internal or ``.msk``, alpha), and NaN.
- **Scale and offset**: applied, so a sample means ``offset + scale * stored`` height units.

Errors are GDAL's own words with the file's name: a compression this build lacks, a driver that cannot open the
file, an unreadable block. rasterio is imported only here and only when a raster is read.
"""

import math
import os
import re
import threading
import warnings
from collections import OrderedDict

import numpy as np

from ..common.errors import InvalidInputError, TesseraError
from .sample_grid import BLOCK_ROWS, CACHE_BYTES, BlockSource, block_shape

#: Bytes of GDAL's own block cache (GDAL_CACHEMAX; its default is 5 % of the RAM). Decoded blocks are kept by the
#: sources themselves (`CACHE_BYTES`), so GDAL needs only enough for the tiles of one band of rows.
GDAL_CACHE_BYTES = 32 * 2**20
#: Band unit names (GDAL's GetUnitType, lower case) -> metres.
UNIT_METRES = {
    "m": 1.0, "metre": 1.0, "meter": 1.0, "metres": 1.0, "meters": 1.0,
    "ft": 0.3048, "foot": 0.3048, "feet": 0.3048, "international foot": 0.3048, "foot (international)": 0.3048,
    "us survey foot": 1200.0 / 3937.0, "us_survey_foot": 1200.0 / 3937.0, "ftus": 1200.0 / 3937.0,
    "us-ft": 1200.0 / 3937.0, "survey foot": 1200.0 / 3937.0, "foot_us": 1200.0 / 3937.0,
    "cm": 0.01, "centimetre": 0.01, "centimeter": 0.01, "mm": 0.001, "millimetre": 0.001, "millimeter": 0.001,
    "dm": 0.1, "decimetre": 0.1, "decimeter": 0.1, "km": 1000.0, "kilometre": 1000.0, "kilometer": 1000.0,
}
_VERTICAL_UNIT = re.compile(r'(?:VERT_CS|VERTCRS|VERTICALCRS)\[.*?(?:LENGTHUNIT|UNIT)\["([^"]*)",\s*([0-9.eE+-]+)',
                            re.S)

_lock = threading.Lock()
_configured = False


def available():
    """Whether GDAL can be used (the bundled rasterio imports); False where this platform's zip has no wheel."""
    return why_not() == ""


def why_not():
    """Why GDAL cannot be used here ("" when it can): the import's own words."""
    try:
        _rasterio()
    except TesseraError as err:
        return str(err)
    return ""


def _rasterio():
    global _configured
    try:
        import rasterio
        import rasterio.vrt  # noqa: F401 -- the warp, imported with the module so a broken install shows here
    except Exception as err:  # an ImportError, or a bundled library that does not load on this system
        raise TesseraError(f"GDAL (rasterio) is not available: {err}") from err
    with _lock:
        if not _configured:
            from rasterio.env import set_gdal_config

            set_gdal_config("GDAL_CACHEMAX", GDAL_CACHE_BYTES)  # bytes (rasterio calls GDALSetCacheMax64)
            set_gdal_config("GDAL_NUM_THREADS", "ALL_CPUS")  # a band of tiles decompressed on every core
            _configured = True
    return rasterio


def _gdal_words(err):
    """GDAL's message of a rasterio error, without rasterio's prefixes."""
    return " ".join(str(err).split()) or type(err).__name__


def _picture(ds):
    from rasterio.enums import ColorInterp

    colours = {ColorInterp.red, ColorInterp.green, ColorInterp.blue, ColorInterp.alpha, ColorInterp.palette}
    return ds.count >= 3 and (set(ds.colorinterp) & colours or ds.dtypes[0] == "uint8")


def _north_up(t):
    return t.b == 0 and t.d == 0 and t.a > 0 and t.e < 0


def open_dataset(path, band=0):
    """Open ``path`` with GDAL for elevation: ``(dataset, band, warped, notes)``. ``band`` 0 picks the only band
    (or the first of a raster that is not a picture); a raster that is not north up comes back as a virtual
    north-up warp. The caller closes both (`close`)."""
    rasterio = _rasterio()
    from rasterio.errors import NotGeoreferencedWarning, RasterioError

    name = os.path.basename(path)
    if not os.path.isfile(path):
        raise InvalidInputError(f"No such elevation file: {path}")
    try:
        with warnings.catch_warnings():  # a TIFF without placement is a plain height map, not a warning
            warnings.simplefilter("ignore", NotGeoreferencedWarning)
            ds = rasterio.open(path)
    except RasterioError as err:
        raise InvalidInputError(f"GDAL cannot open {name}: {_gdal_words(err)}") from err
    try:
        notes = []
        if band == 0:
            if ds.count > 1 and _picture(ds):
                raise InvalidInputError(f"{name} is a picture ({ds.count} bands of {ds.dtypes[0]}, "
                                        f"{'/'.join(c.name for c in ds.colorinterp)}), not elevation data: choose "
                                        "the band that holds the heights (Band)")
            if ds.count > 1:
                notes.append(f"band 1 of {ds.count}")
            band = 1
        elif not 1 <= band <= ds.count:
            raise InvalidInputError(f"{name} has {ds.count} band{'s' * (ds.count > 1)}; Band {band} does not exist")
        dtype = np.dtype(ds.dtypes[band - 1])
        if dtype.kind not in "iuf":
            raise InvalidInputError(f"{name} stores {dtype.name} samples (complex numbers); elevation data must be "
                                    "integers or floats")
        gcps, gcp_crs = ds.gcps
        if ds.transform.is_identity and not gcps:  # no placement: a plain image
            return ds, band, None, notes
        if ds.transform.is_identity:
            if len(gcps) < 3 or gcp_crs is None:
                raise InvalidInputError(f"{name} is placed by {len(gcps)} control point{'s' * (len(gcps) != 1)}"
                                        f"{'' if gcp_crs else ' without a coordinate system'}; at least 3 with one "
                                        "are needed to warp it onto a grid")
            notes.append(f"warped north up from {len(gcps)} control points (bilinear)")
            return ds, band, _warp(ds, name, gcp_crs), notes
        if not _north_up(ds.transform):
            if ds.crs is None:
                raise InvalidInputError(f"{name} is not north up and has no coordinate system to warp it in: "
                                        "warp it north up first (gdalwarp)")
            t = ds.transform
            what = "south-up rows" if t.b == 0 and t.d == 0 and t.a > 0 else "a rotated, sheared or mirrored grid"
            notes.append(f"warped north up from {what} (bilinear)")
            return ds, band, _warp(ds, name, ds.crs), notes
        return ds, band, None, notes
    except BaseException:
        ds.close()
        raise


def _warp(ds, name, crs):
    from rasterio.enums import Resampling
    from rasterio.errors import RasterioError
    from rasterio.vrt import WarpedVRT

    try:
        # float32 with NaN outside the source: what the warp adds is a void, never a height of 0
        return WarpedVRT(ds, resampling=Resampling.bilinear, dtype="float32", nodata=float("nan"), crs=crs)
    except RasterioError as err:
        raise InvalidInputError(f"GDAL cannot warp {name} north up: {_gdal_words(err)}") from err


def close(ds, warped):
    if warped is not None:
        warped.close()
    ds.close()


def vertical_metres(ds, band, name):
    """Metres per stored height unit of ``band`` and whether the file said so: ``(metres, stated)``."""
    unit = (ds.units[band - 1] or "").strip()
    if unit:
        metres = UNIT_METRES.get(unit.lower())
        if metres is None:
            raise InvalidInputError(f"{name} gives its heights in {unit!r}, which Tessera does not know "
                                    "(metre, foot, US survey foot, centimetre...)")
        return metres, True
    if ds.crs is not None:
        match = _VERTICAL_UNIT.search(ds.crs.to_wkt())
        if match:
            return float(match.group(2)), True
    return 1.0, False


def horizontal(ds, name):
    """``(geographic, metres per horizontal unit, EPSG code or 0)`` of ``ds``'s CRS (PROJ resolves the units)."""
    from rasterio.errors import CRSError

    crs = ds.crs
    try:
        code = crs.to_epsg() or 0
    except CRSError:
        code = 0
    if crs.is_geographic:
        unit, factor = crs.units_factor
        if not math.isclose(factor, math.pi / 180.0, rel_tol=1e-9):
            raise InvalidInputError(f"{name} gives its angles in {unit}; Tessera reads degrees")
        return True, 1.0, code
    try:
        unit, factor = crs.linear_units_factor
    except CRSError as err:
        raise InvalidInputError(f"{name}'s coordinate system has no linear unit GDAL can resolve: "
                                f"{_gdal_words(err)}") from err
    if not (np.isfinite(factor) and factor > 0):
        raise InvalidInputError(f"{name} gives its positions in {unit!r} ({factor!r} m), which cannot be used")
    return False, float(factor), code


class GdalSource(BlockSource):
    """One band of a GDAL raster, decoded a block at a time (`sample_grid.BlockSource`; file order: row 0 at the
    top); float32 heights in stored units after the band's scale and offset, voids (no-data, the mask band, NaN) as
    NaN. The dataset stays open while the source lives (opened again after pickling or `close`)."""

    def __init__(self, path, band=1, warp=False, shape=None):
        self.path, self.band, self.warp = path, band, warp
        self._handles = None
        self._io = threading.Lock()
        ds, src = self._open()
        self.shape = shape or (src.height, src.width)
        # a warp is read in whole-width bands: GDAL's warper approximates its transform per chunk, so its values may
        # depend on the window asked for; the same bands for every reader keep every sample one value
        if warp:
            self.block_rows = BLOCK_ROWS
        else:
            tile = tuple(int(v) for v in src.block_shapes[band - 1])
            self.block_rows, cols = block_shape(tile, src.width, src.height)
            self.block_cols = 0 if cols >= self.shape[1] else cols
        self._init_cache(CACHE_BYTES)
        self.scale = float(ds.scales[band - 1] or 1.0)
        self.offset = float(ds.offsets[band - 1] or 0.0)
        from rasterio.enums import MaskFlags

        flags = set(src.mask_flag_enums[0 if warp else band - 1])
        self._mask = bool(flags & {MaskFlags.per_dataset, MaskFlags.alpha}) and not warp
        nodata = src.nodatavals[0 if warp else band - 1]
        self.nodata = None if nodata is None else float(nodata)

    def _open(self):
        if self._handles is None:
            ds, band, warped, _ = open_dataset(self.path, self.band)
            self._handles = (ds, warped)
        ds, warped = self._handles
        return ds, warped if self.warp else ds

    def close(self):
        if self._handles is not None:
            close(*self._handles)
            self._handles = None

    def __del__(self):
        try:
            self.close()
        except Exception:  # noqa: S110 -- at interpreter exit GDAL may be gone
            pass

    def __getstate__(self):
        state = dict(self.__dict__)
        state.update(_handles=None, _cache=OrderedDict(), _io=None)
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._io = threading.Lock()

    def _span(self, bi, bj):
        with self._io:  # one dataset handle: GDAL's are not shared between threads (nor is the cache)
            return super()._span(bi, bj)

    def _prefetch(self, bi, columns):
        with self._io:
            return super()._prefetch(bi, columns)

    def _decode(self, r0, r1, c0, c1):
        from rasterio.errors import RasterioError
        from rasterio.windows import Window

        window = Window(c0, r0, c1 - c0, r1 - r0)
        _, src = self._open()
        b = 1 if self.warp else self.band
        try:
            raw = src.read(b, window=window)
            mask = src.read_masks(b, window=window) if self._mask else None
        except RasterioError as err:
            raise InvalidInputError(f"Reading rows {r0}-{r1 - 1} of {os.path.basename(self.path)} failed: "
                                    f"{_gdal_words(err)}") from err
        return self._heights(raw, None if mask is None else mask == 0)

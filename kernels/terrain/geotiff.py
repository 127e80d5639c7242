"""Elevation data as GIS tools write it (SRTM, Copernicus DEM, USGS 3DEP, national lidar DEMs): placement, units,
voids, several files as one grid.

Files are read through GDAL (`gdal_raster`: GeoTIFF with every compression, BigTIFF, COG, ``.hgt``, ``.asc``,
``.img``, ``.vrt``...) where the bundled rasterio imports; where it does not (a platform without a wheel, a broken
install), GeoTIFFs are read here from their tags with tifffile [tifffile] and their samples with OpenImageIO, a
block at a time (`sample_grid`), and what only GDAL resolves (a unit named only by an EPSG code this module does
not list, a mask band) is refused with that reason. What is taken from the file:

- **Placement** (`GeoInfo`): the model coordinates of the first sample's centre and the sample spacing.
  *PixelIsArea* files (the usual) put a sample at the centre of its pixel, *PixelIsPoint* files on the tie point
  itself. GDAL warps a rotated, sheared or south-up raster north up; the TIFF reader refuses it with the reason.
- **Units**: horizontal and vertical from the CRS (metre, foot, US survey foot; metres where the file does not
  say, noted). Geographic files (degrees) are measured at the data's centre on the WGS 84 ellipsoid.
- **No-data**: the no-data value (-32768, -9999, the lowest float32, NaN...), the mask band, NaN samples. Voids are
  filled or cut (`void_fill`), never a height.
- **Scale and offset** (a sample means ``offset + scale * stored``): applied by the sources.

Several files of one DEM (adjacent tiles, each with its own placement) are laid on one grid when they share the
sample spacing, the units and the grid: their offsets must be whole samples. Samples no file covers are voids.
"""

import hashlib
import math
import os
from dataclasses import dataclass

import numpy as np

from ..common.errors import InvalidInputError, TesseraError
from . import gdal_raster
from .sample_grid import Mosaic, TiffSource, tiff_layout

#: EPSG unit codes (GeoTIFF 1.1, §B.4) -> metres.
LINEAR_UNITS = {9001: 1.0, 9002: 0.3048, 9003: 1200.0 / 3937.0, 9030: 1852.0, 9036: 1000.0}
#: WGS 84 semi-major axis (m) and first eccentricity squared, for metres per degree of geographic files.
WGS84_A, WGS84_E2 = 6378137.0, 6.69437999014e-3
#: Relative difference within which two files' spacings and grid offsets count as equal.
GRID_TOLERANCE = 1e-6


@dataclass(frozen=True)
class GeoInfo:
    """One file's placement: ``origin`` (x, y) model coordinates of the centre of the file's top-left sample,
    ``spacing`` (dx, dy) > 0 model units between samples east and south, ``size`` (width, height) in samples,
    ``geographic`` (degrees) or projected, ``metres`` per horizontal model unit (projected files), ``vertical``
    metres per stored height unit, ``nodata`` (None: none), ``crs`` (EPSG code or 0) and ``crs_text`` (the CRS as
    GDAL names it; "" for the TIFF reader), ``height_scale`` and ``height_offset`` (a sample means
    ``offset + scale * stored``; the sources apply them), ``quantum`` the step between heights an integer file can
    hold (stored units after the scale; 0 for floats), ``band`` (1-based), ``warp`` (read through a north-up warp),
    ``reader`` ("gdal" or "tiff"), ``notes`` what the reader decided that the user should know."""

    path: str
    origin: tuple
    spacing: tuple
    size: tuple
    geographic: bool
    metres: float
    vertical: float
    nodata: float | None
    crs: int
    crs_text: str = ""
    height_scale: float = 1.0
    height_offset: float = 0.0
    quantum: float = 0.0
    band: int = 1
    warp: bool = False
    reader: str = "tiff"
    notes: tuple = ()


#: Projected EPSG codes in metres that the TIFF reader knows without GDAL (UTM on WGS 84, NAD83, ETRS89, NAD27;
#: Web Mercator, LAEA Europe, Lambert-93, British National Grid, GDA94/GDA2020 MGA).
_METRE_CRS = (*((a, b) for a, b in ((32601, 32660), (32701, 32760), (26901, 26923), (25828, 25838), (26701, 26722),
                                      (28348, 28358), (7846, 7859))), (3857, 3857), (3035, 3035), (2154, 2154),
              (27700, 27700))
#: Vertical EPSG codes -> metres per unit that the TIFF reader knows without GDAL.
_VERTICAL_CRS = {5703: 1.0, 5773: 1.0, 3855: 1.0, 5701: 1.0, 5714: 1.0, 7837: 1.0, 5783: 1.0, 6360: 1200.0 / 3937.0,
                 8228: 0.3048}


def _key(tags, name):
    value = tags.get(name)
    return None if value is None else int(value)


def read_geoinfo(path, band=0):
    """The `GeoInfo` of an elevation raster, or None when the file carries no placement (a plain height-map image).

    Read through GDAL where the bundled rasterio imports (every format GDAL reads), otherwise from the TIFF tags.
    ``band``: 0 picks the height band (a picture's colour bands are refused), N the N-th. Raises
    `InvalidInputError` naming the file and the reason for what cannot be read or placed."""
    if gdal_raster.available():
        return _gdal_geoinfo(path, band)
    if not is_tiff(path):
        raise InvalidInputError(f"{os.path.basename(path)}: this Tessera reads only GeoTIFF files, because GDAL "
                                f"(rasterio) is not available on this system ({gdal_raster.why_not()})")
    return _tiff_geoinfo(path)


def is_tiff(path):
    """Whether ``path`` names a TIFF by its extension."""
    return path.lower().endswith((".tif", ".tiff"))


#: Extensions of the elevation files read with their placement: GeoTIFF, SRTM tiles, ESRI ASCII and binary grids,
#: ERDAS Imagine, GDAL virtual mosaics, USGS DEM, DTED. (GDAL reads more; these are the ones the file browser lists.)
ELEVATION_EXTENSIONS = (".tif", ".tiff", ".hgt", ".asc", ".img", ".vrt", ".dem", ".bil", ".flt", ".dt0", ".dt1",
                        ".dt2")


def is_elevation_file(path):
    """Whether ``path`` names a file that may carry a placement (a GeoTIFF or another elevation format)."""
    return path.lower().endswith(ELEVATION_EXTENSIONS)


def _gdal_geoinfo(path, band):
    name = os.path.basename(path)
    ds, band, warped, notes = gdal_raster.open_dataset(path, band)
    try:
        src = warped or ds
        if src.transform.is_identity:
            return None
        t = src.transform
        if not (np.isfinite([t.a, t.e, t.c, t.f]).all() and t.a > 0 and t.e < 0):
            raise InvalidInputError(f"{name} has an unusable sample spacing ({t.a!r}, {-t.e!r})")
        if src.crs is None:
            geographic, metres, code, text = False, 1.0, 0, ""
            notes.append("no coordinate system: positions read as metres")
        else:
            geographic, metres, code = gdal_raster.horizontal(src, name)
            text = src.crs.to_string()
        vertical, stated = gdal_raster.vertical_metres(ds, band, name)
        if not stated:
            notes.append("heights read as metres (the file names no vertical unit)")
        dtype = np.dtype(ds.dtypes[band - 1])
        scale, offset = float(ds.scales[band - 1] or 1.0), float(ds.offsets[band - 1] or 0.0)
        if scale != 1.0 or offset != 0.0:
            notes.append(f"stored values x {scale:g} + {offset:g}")
        x0, y0 = t.c + 0.5 * t.a, t.f + 0.5 * t.e  # GDAL gives pixel corners for PixelIsPoint files too
        nodata = ds.nodatavals[band - 1]
        return GeoInfo(path, (float(x0), float(y0)), (float(t.a), float(-t.e)), (src.width, src.height), geographic,
                       metres, vertical, None if nodata is None else float(nodata), code, text, scale, offset,
                       abs(scale) if dtype.kind in "iu" else 0.0, band, warped is not None, "gdal", tuple(notes))
    finally:
        gdal_raster.close(ds, warped)


def _gdal_metadata_scale(page):
    """(scale, offset) of band 0 from the GDAL_METADATA tag (42112, XML), (1, 0) where it says none."""
    import xml.etree.ElementTree as ET

    tag = page.tags.get(42112)
    found = {"scale": 1.0, "offset": 0.0}
    if tag is not None:
        try:
            items = ET.fromstring(str(tag.value)).iter("Item")
        except ET.ParseError:
            items = ()
        for item in items:
            role = (item.get("role") or "").lower()
            if role in found and item.get("sample", "0") == "0":
                try:
                    found[role] = float(item.text)
                except (TypeError, ValueError):
                    raise InvalidInputError(f"{os.path.basename(page.parent.filehandle.path)} has a band {role} "
                                            f"that is not a number: {item.text!r}") from None
    return found["scale"], found["offset"]


def _tiff_geoinfo(path):
    """The placement of a GeoTIFF read with tifffile (no GDAL): a `GeoInfo`, or None when the file has no GeoTIFF
    keys. Raises `InvalidInputError` with what to do for what only GDAL could read."""
    name = os.path.basename(path)
    page = _tiff_page(path, name)
    tags = page["tags"]
    if not tags:
        return None
    if page["masked"]:
        raise InvalidInputError(f"{name} marks its voids with a mask band, which Tessera reads only through GDAL, "
                                f"not available on this system ({gdal_raster.why_not()})")
    x0, y0, dx, dy = _tiff_placement(name, tags)
    geographic = _key(tags, "GTModelTypeGeoKey") == 2
    unit = _key(tags, "ProjLinearUnitsGeoKey")
    crs = _key(tags, "GeographicTypeGeoKey" if geographic else "ProjectedCSTypeGeoKey") or 0
    if not geographic and unit is None and crs and not any(a <= crs <= b for a, b in _METRE_CRS):
        raise InvalidInputError(f"{name} names its unit only through EPSG code {crs}, which Tessera resolves only "
                                f"through GDAL, not available on this system ({gdal_raster.why_not()})")
    if not geographic and unit is not None and unit not in LINEAR_UNITS:
        raise InvalidInputError(f"{name} gives its positions in unit code {unit}, which Tessera does not know "
                                "(metre, foot, US survey foot, kilometre, nautical mile)")
    angular = _key(tags, "GeogAngularUnitsGeoKey")
    if geographic and angular not in (None, 9102):
        raise InvalidInputError(f"{name} gives its angles in unit code {angular}; Tessera reads degrees (9102)")
    notes = []
    vertical_metres = _tiff_vertical_metres(name, tags, notes)
    nodata = page["nodata"]
    if nodata is not None:
        try:
            nodata = float(str(nodata).strip().rstrip("\x00"))
        except ValueError as err:
            raise InvalidInputError(f"{name} has a no-data value that is not a number: {nodata!r}") from err
    band_scale, band_offset = page["scale"]
    if band_scale != 1.0 or band_offset != 0.0:
        notes.append(f"stored values x {band_scale:g} + {band_offset:g}")
    return GeoInfo(path, (float(x0), float(y0)), (float(dx), float(dy)), page["size"], geographic,
                   LINEAR_UNITS.get(unit, 1.0), vertical_metres, nodata, crs, "", band_scale, band_offset,
                   abs(band_scale) if page["integer"] else 0.0, 1, False, "tiff", tuple(notes))


def _tiff_page(path, name):
    """What `_tiff_geoinfo` reads of a TIFF's first page: {tags: its GeoTIFF keys, nodata: the GDAL no-data tag's
    value or None, size: (width, height), integer: whether its samples are integers, masked: whether a mask band
    follows, scale: (scale, offset) of its values}."""
    try:
        import tifffile
    except ImportError as err:  # bundled with the extension; only a broken install lacks it
        raise TesseraError(f"tifffile is not available ({err}): GeoTIFF files cannot be read") from err
    try:
        with tifffile.TiffFile(path) as tf:
            page = tf.pages.first
            return {
                "tags": page.geotiff_tags or {},
                # tifffile drops a no-data value at the edge of float32 (GDAL's -3.4028234663852886e+38) as 0
                "nodata": page.tags[42113].value if 42113 in page.tags else None,
                "size": (int(page.imagewidth), int(page.imagelength)),
                "integer": page.dtype is not None and np.dtype(page.dtype).kind in "iu",
                "masked": any(int(p.subfiletype) & 4 for p in tf.pages[1:]),
                "scale": _gdal_metadata_scale(page),
            }
    except (tifffile.TiffFileError, OSError, ValueError, IndexError, KeyError) as err:
        raise InvalidInputError(f"{name} is not a TIFF file that can be read: {err}") from err


def _tiff_placement(name, tags):
    """The first sample's centre and the sample spacing from a GeoTIFF's keys: (x0, y0, dx, dy), north up."""
    scale, tie, matrix = tags.get("ModelPixelScale"), tags.get("ModelTiepoint"), tags.get("ModelTransformation")
    if tie is not None:  # tifffile gives one tie point flat, several as a list of six-value lists
        tie = np.asarray(tie, np.float64).ravel()
    if matrix is None and tie is not None and len(tie) > 6:
        raise InvalidInputError(f"{name} is placed by {len(tie) // 6} tie points (a warp, not a grid); "
                                "Tessera needs one tie point and a pixel scale: warp it onto a grid first")
    if matrix is not None:
        m = np.asarray(matrix, np.float64).reshape(4, 4)
        if m[0, 1] != 0 or m[1, 0] != 0:
            raise InvalidInputError(f"{name} is rotated or sheared (its ModelTransformation mixes rows and columns); "
                                    "Tessera needs north-up data: warp it north up first (gdalwarp)")
        dx, dy, x0, y0 = m[0, 0], -m[1, 1], m[0, 3], m[1, 3]
    elif scale is not None and tie is not None and len(tie) == 6:
        i, j, _, x, y, _ = (float(v) for v in tie[:6])
        dx, dy = float(scale[0]), float(scale[1])
        x0, y0 = x - i * dx, y + j * dy
    else:
        missing = "ModelPixelScale" if tie is not None else "ModelTiepoint and ModelPixelScale"
        raise InvalidInputError(f"{name} has GeoTIFF keys but no placement: its {missing} tag is missing")
    if not (np.isfinite([dx, dy, x0, y0]).all() and dx > 0):
        raise InvalidInputError(f"{name} has an unusable sample spacing ({dx!r}, {dy!r})")
    if dy <= 0:
        raise InvalidInputError(f"{name} stores its rows south to north (a negative or zero row spacing); "
                                "Tessera needs north-up data: flip it first (gdalwarp)")
    if _key(tags, "GTRasterTypeGeoKey") != 2:  # PixelIsArea (the default): samples at the pixel centres
        x0, y0 = x0 + 0.5 * dx, y0 - 0.5 * dy
    return x0, y0, dx, dy


def _tiff_vertical_metres(name, tags, notes):
    """Metres per height unit from a GeoTIFF's vertical keys; appends to ``notes`` when the file names none."""
    vertical = _key(tags, "VerticalUnitsGeoKey")
    vertical_crs = _key(tags, "VerticalCSTypeGeoKey")
    if vertical is None and vertical_crs is not None:
        if vertical_crs not in _VERTICAL_CRS:
            raise InvalidInputError(f"{name} names its height unit only through EPSG code {vertical_crs}, which "
                                    "Tessera resolves only through GDAL, not available on this system "
                                    f"({gdal_raster.why_not()})")
        return _VERTICAL_CRS[vertical_crs]
    if vertical is not None and vertical not in LINEAR_UNITS:
        raise InvalidInputError(f"{name} gives its heights in unit code {vertical}, which Tessera does not know "
                                "(metre, foot, US survey foot)")
    if vertical is None:
        notes.append("heights read as metres (the file names no vertical unit)")
    return LINEAR_UNITS.get(vertical, 1.0)


def metres_per_unit(info, latitude=None):
    """Metres per model unit east and north: (mx, my). Geographic files: at ``latitude`` degrees on WGS 84."""
    if not info.geographic:
        return info.metres, info.metres
    phi = math.radians(latitude)
    s2 = math.sin(phi) ** 2
    n = WGS84_A / math.sqrt(1 - WGS84_E2 * s2)  # prime vertical radius
    m = WGS84_A * (1 - WGS84_E2) / (1 - WGS84_E2 * s2) ** 1.5  # meridional radius
    rad = math.pi / 180.0
    return n * math.cos(phi) * rad, m * rad


@dataclass(frozen=True)
class GeoGrid:
    """Several files on one grid: ``grid`` (a `sample_grid.Mosaic`, voids NaN), ``origin`` model (x, y) of the
    grid's top-left sample, ``spacing`` (dx, dy) model units, ``texel`` (tx, ty) metres between samples east and
    north, ``vertical`` metres per height unit, ``files`` the `GeoInfo`s in grid order, ``centre`` model (x, y)
    of the grid's centre."""

    grid: Mosaic
    origin: tuple
    spacing: tuple
    texel: tuple
    vertical: float
    files: tuple

    @property
    def centre(self):
        h, w = self.grid.shape
        return (self.origin[0] + 0.5 * (w - 1) * self.spacing[0], self.origin[1] - 0.5 * (h - 1) * self.spacing[1])


def open_geotiffs(paths, band=0):
    """Lay the elevation files ``paths`` on one grid: a `GeoGrid`. Files without a placement, or that do not share
    one grid (spacing, units, CRS, whole-sample offsets), are refused with the file's name and the reason.
    ``band``: see `read_geoinfo`."""
    infos = []
    for path in sorted(paths):
        if not os.path.isfile(path):
            raise InvalidInputError(f"No such elevation file: {path}")
        info = read_geoinfo(path, band)
        if info is None:
            raise InvalidInputError(f"{os.path.basename(path)} has no placement (no GeoTIFF tags or geotransform); "
                                    "load it as a height-map image and give its Texel Size")
        infos.append(info)
    if not infos:
        raise InvalidInputError("Choose at least one GeoTIFF file")
    first = infos[0]
    for info in infos[1:]:
        name = os.path.basename(info.path)
        for what, a, b in (("CRS", info.crs, first.crs), ("CRS", info.crs_text, first.crs_text),
                           ("geographic or projected kind", info.geographic, first.geographic),
                           ("units", info.metres, first.metres), ("height units", info.vertical, first.vertical)):
            if a != b:
                raise InvalidInputError(f"{name} and {os.path.basename(first.path)} differ in {what} ({a} and {b}): "
                                        "files of one terrain must share one grid")
        if not np.allclose(info.spacing, first.spacing, rtol=GRID_TOLERANCE, atol=0):
            raise InvalidInputError(f"{name} has a sample spacing of {info.spacing}, "
                                    f"{os.path.basename(first.path)} {first.spacing}: files of one terrain must share "
                                    "one spacing")
    dx, dy = first.spacing
    offsets = []
    for info in infos:
        col = (info.origin[0] - first.origin[0]) / dx
        row = (first.origin[1] - info.origin[1]) / dy
        if abs(col - round(col)) > 1e-3 or abs(row - round(row)) > 1e-3:
            raise InvalidInputError(f"{os.path.basename(info.path)} sits {col:.4f} columns and {row:.4f} rows from "
                                    f"{os.path.basename(first.path)}: not on the same grid of samples")
        offsets.append((round(col), round(row)))
    c0 = min(c for c, _ in offsets)
    r0 = min(r for _, r in offsets)
    width = max(c + i.size[0] for (c, _), i in zip(offsets, infos, strict=True)) - c0
    height = max(r + i.size[1] for (_, r), i in zip(offsets, infos, strict=True)) - r0
    placements = []
    for (c, r), info in zip(offsets, infos, strict=True):
        placements.append((_source(info), c - c0, r - r0))
    origin = (first.origin[0] + c0 * dx, first.origin[1] - r0 * dy)
    grid = Mosaic(placements, width, height)
    centre_lat = origin[1] - 0.5 * (height - 1) * dy
    if first.geographic and not -90 < centre_lat < 90:
        raise InvalidInputError(f"{os.path.basename(first.path)} is geographic but its centre lies at latitude "
                                f"{centre_lat:g}")
    mx, my = metres_per_unit(first, centre_lat if first.geographic else None)
    return GeoGrid(grid, origin, (dx, dy), (dx * mx, dy * my), first.vertical, tuple(infos))


def _source(info):
    """The block reader of one file's samples (file order, voids NaN, scale and offset applied)."""
    if info.reader == "gdal":
        return gdal_raster.GdalSource(info.path, info.band, info.warp, (info.size[1], info.size[0]))
    layout = tiff_layout(info.path)
    if (layout.width, layout.height) != info.size:
        raise InvalidInputError(f"{os.path.basename(info.path)}: OpenImageIO and the TIFF header disagree on "
                                "its size (a damaged file)")
    return TiffSource(info.path, layout, info.nodata, info.height_scale, info.height_offset)


def read_geotiff(paths, voids="FILL", budget_bytes=0, exaggeration=1.0, unit_metres=1.0, progress=None, band=0,
                 void_index=None):
    """A terrain `HeightMap` from GeoTIFFs ``paths`` (one DEM, one file or several adjacent ones) and its
    `GeoGrid`: ``(hm, geo)``.

    voids: "FILL" (filled from their valid neighbours) or "HOLES" (filled for the analysis, cut from the mesh);
    budget_bytes: the memory budget the void windows must fit; exaggeration: a factor on the heights; unit_metres:
    metres per world unit (Blender's Unit Scale), so texels and heights come out in scene units;
    progress(done, total): the void scan's bands; band: see `read_geoinfo`; void_index: the path of a void index
    `write_void_index` made of the same data (a farm's tasks share one): the voids are taken from it, not scanned, so
    only the windows asked for are ever read. Heights are ``exaggeration * vertical / unit_metres * sample``: a valid
    sample keeps its value exactly when the factor is 1."""
    from .heightmap_io import HeightMap

    if not (np.isfinite(unit_metres) and unit_metres > 0):
        raise InvalidInputError(f"The unit scale must be positive; got {unit_metres!r}")
    geo, filled = _filled_grid(paths, voids, budget_bytes, progress, band, void_index)
    tx, ty = (t / unit_metres for t in geo.texel)
    same = abs(tx - ty) <= GRID_TOLERANCE * tx
    scale = exaggeration * geo.vertical / unit_metres
    quantum = max(info.quantum for info in geo.files) * abs(scale)  # integer files: their step, in world units
    hm = HeightMap(filled, texel_size=tx, texel_size_y=0.0 if same else ty, scale=scale, source=filled.name,
                   quantum=quantum)
    return hm, geo


def _filled_grid(paths, voids, budget_bytes, progress, band, void_index=None):
    """The `GeoGrid` of ``paths`` and its samples with the voids filled (`void_fill.FilledGrid`)."""
    from .void_fill import FilledGrid, VoidIndex

    if voids not in ("FILL", "HOLES"):
        raise InvalidInputError(f"Voids must be FILL or HOLES; got {voids!r}")
    geo = open_geotiffs(paths, band)
    names = ", ".join(os.path.basename(i.path) for i in geo.files)
    index = None
    if void_index is not None:
        index = VoidIndex(void_index)
        made_of = index.header.get("source")
        if made_of != data_fingerprint(geo, band):
            raise InvalidInputError(f"The void index {os.path.basename(void_index)} was made of other data than "
                                    f"{names} (a file was changed or replaced since): make the farm plan again")
    return geo, FilledGrid(geo.grid, cut=voids == "HOLES", budget_bytes=budget_bytes, name=names,
                           progress=progress, index=index)


#: Bytes read from each end of a file for its fingerprint (the TIFF header and tile tables live there).
FINGERPRINT_BYTES = 64 * 1024


def data_fingerprint(geo, band=0):
    """What identifies the samples of a `GeoGrid` cheaply on every machine of a farm that sees the same files: each
    file's name, size, modification time (whole seconds: file-sharing protocols keep no finer one alike) and a hash of
    its first and last `FINGERPRINT_BYTES` (the header and tile tables), its place on the grid, and the band: a hex
    string. Reading the whole file would defeat the point (a task reads only its block)."""
    digest = hashlib.sha256(f"band {band}".encode())
    for (source, col, row), info in zip(geo.grid.placements, geo.files, strict=True):
        st = os.stat(info.path)
        size = st.st_size
        digest.update(f"|{os.path.basename(info.path)} {size} {int(st.st_mtime)} {col} {row} {source.shape}|".encode())
        with open(info.path, "rb") as f:
            digest.update(f.read(FINGERPRINT_BYTES))
            f.seek(max(0, size - FINGERPRINT_BYTES))
            digest.update(f.read(FINGERPRINT_BYTES))
    return digest.hexdigest()


def write_void_index(paths, path, voids="FILL", budget_bytes=0, progress=None, band=0):
    """Scan the elevation files ``paths`` for voids once, fill them, and write the result to ``path`` for the tasks
    of a farm (`read_geotiff`'s ``void_index``): returns the count of void samples. Reads the whole data once; the
    caller makes the write whole (a temporary name, then a rename)."""
    geo, filled = _filled_grid(paths, voids, budget_bytes, progress, band)
    filled.save_index(path, data_fingerprint(geo, band))
    return filled.void_count

"""GeoTIFF elevation data (SRTM, Copernicus DEM, USGS 3DEP, national lidar DEMs): placement, units, voids.

The GeoTIFF tags are read with tifffile [tifffile] (the header only); the samples with OpenImageIO, a block at
a time (`sample_grid`), so a file of any size is never decoded whole. What is taken from the file:

- **Placement** (`GeoInfo`): the model coordinates of the first sample's centre and the sample spacing, from
  ModelPixelScale + ModelTiepoint or from a ModelTransformation without rotation; *PixelIsArea* files (the
  usual) put a sample at the centre of its pixel, *PixelIsPoint* files on the tie point itself. North must be up:
  a rotated or sheared transform, or one whose rows run south to north, is refused with the reason.
- **Units**: horizontal from ProjLinearUnitsGeoKey, vertical from VerticalUnitsGeoKey (metre, foot, US survey
  foot; metres where the file does not say). Geographic files (degrees) are measured at the data's centre on
  the WGS 84 ellipsoid (metres per degree east and north).
- **No-data**: the GDAL_NODATA tag (-32768, -9999, NaN...); NaN samples are voids too. Voids are filled or cut
  (`void_fill`), never a height.

Several files of one DEM (adjacent tiles, each with its own placement) are laid on one grid when they share the
sample spacing, the units and the grid: their offsets must be whole samples. Samples no file covers are voids.
"""

import math
import os
from dataclasses import dataclass

import numpy as np

from ..common.errors import InvalidInputError, TesseraError
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
    metres per stored height unit, ``nodata`` (None: none), ``crs`` (EPSG code or 0)."""

    path: str
    origin: tuple
    spacing: tuple
    size: tuple
    geographic: bool
    metres: float
    vertical: float
    nodata: float | None
    crs: int


def _key(tags, name):
    value = tags.get(name)
    return None if value is None else int(value)


def read_geoinfo(path):
    """The `GeoInfo` of a GeoTIFF, or None when the TIFF carries no GeoTIFF tags (a plain height-map image).

    Raises `InvalidInputError` naming the file for what cannot be placed: a rotated transform, south-up rows,
    a tie point without a pixel scale, unknown units."""
    name = os.path.basename(path)
    try:
        import tifffile
    except ImportError as err:  # bundled with the extension; only a broken install lacks it
        raise TesseraError(f"tifffile is not available ({err}): GeoTIFF files cannot be read") from err
    try:
        with tifffile.TiffFile(path) as tf:
            page = tf.pages.first
            tags = page.geotiff_tags or {}
            nodata = page.nodata if 42113 in page.tags else None
            width, height = int(page.imagewidth), int(page.imagelength)
    except (tifffile.TiffFileError, OSError, ValueError, IndexError, KeyError) as err:
        raise InvalidInputError(f"{name} is not a TIFF file that can be read: {err}") from err
    if not tags:
        return None
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
    geographic = _key(tags, "GTModelTypeGeoKey") == 2
    unit = _key(tags, "ProjLinearUnitsGeoKey")
    if not geographic and unit is not None and unit not in LINEAR_UNITS:
        raise InvalidInputError(f"{name} gives its positions in unit code {unit}, which Tessera does not know "
                                "(metre, foot, US survey foot, kilometre, nautical mile)")
    angular = _key(tags, "GeogAngularUnitsGeoKey")
    if geographic and angular not in (None, 9102):
        raise InvalidInputError(f"{name} gives its angles in unit code {angular}; Tessera reads degrees (9102)")
    vertical = _key(tags, "VerticalUnitsGeoKey")
    if vertical is not None and vertical not in LINEAR_UNITS:
        raise InvalidInputError(f"{name} gives its heights in unit code {vertical}, which Tessera does not know "
                                "(metre, foot, US survey foot)")
    crs = _key(tags, "GeographicTypeGeoKey" if geographic else "ProjectedCSTypeGeoKey") or 0
    nodata = None if nodata is None else float(nodata)
    return GeoInfo(path, (float(x0), float(y0)), (float(dx), float(dy)), (width, height), geographic,
                   LINEAR_UNITS.get(unit, 1.0), LINEAR_UNITS.get(vertical, 1.0), nodata, crs)


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


def open_geotiffs(paths):
    """Lay the GeoTIFFs ``paths`` on one grid: a `GeoGrid`. Files that are not GeoTIFFs, or that do not share
    one grid (spacing, units, CRS, whole-sample offsets), are refused with the file's name and the reason."""
    infos = []
    for path in sorted(paths):
        if not os.path.isfile(path):
            raise InvalidInputError(f"No such elevation file: {path}")
        info = read_geoinfo(path)
        if info is None:
            raise InvalidInputError(f"{os.path.basename(path)} has no GeoTIFF tags (no placement); load it as a "
                                    "height-map image and give its Texel Size")
        infos.append(info)
    if not infos:
        raise InvalidInputError("Choose at least one GeoTIFF file")
    first = infos[0]
    for info in infos[1:]:
        name = os.path.basename(info.path)
        for what, a, b in (("CRS", info.crs, first.crs), ("geographic or projected kind", info.geographic,
                                                          first.geographic), ("units", info.metres, first.metres),
                           ("height units", info.vertical, first.vertical)):
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
        layout = tiff_layout(info.path)
        if (layout.width, layout.height) != info.size:
            raise InvalidInputError(f"{os.path.basename(info.path)}: OpenImageIO and the TIFF header disagree on "
                                    "its size (a damaged file)")
        placements.append((TiffSource(info.path, layout, info.nodata), c - c0, r - r0))
    origin = (first.origin[0] + c0 * dx, first.origin[1] - r0 * dy)
    grid = Mosaic(placements, width, height)
    centre_lat = origin[1] - 0.5 * (height - 1) * dy
    if first.geographic and not -90 < centre_lat < 90:
        raise InvalidInputError(f"{os.path.basename(first.path)} is geographic but its centre lies at latitude "
                                f"{centre_lat:g}")
    mx, my = metres_per_unit(first, centre_lat if first.geographic else None)
    return GeoGrid(grid, origin, (dx, dy), (dx * mx, dy * my), first.vertical, tuple(infos))


def read_geotiff(paths, voids="FILL", budget_bytes=0, exaggeration=1.0, unit_metres=1.0, progress=None):
    """A terrain `HeightMap` from GeoTIFFs ``paths`` (one DEM, one file or several adjacent ones) and its
    `GeoGrid`: ``(hm, geo)``.

    voids: "FILL" (filled from their valid neighbours) or "HOLES" (filled for the analysis, cut from the mesh);
    budget_bytes: the memory budget the void windows must fit; exaggeration: a factor on the heights; unit_metres:
    metres per world unit (Blender's Unit Scale), so texels and heights come out in scene units;
    progress(done, total): the void scan's bands. Heights are ``exaggeration * vertical / unit_metres * sample``:
    a valid sample keeps its value exactly when the factor is 1."""
    from .heightmap_io import HeightMap
    from .void_fill import FilledGrid

    if voids not in ("FILL", "HOLES"):
        raise InvalidInputError(f"Voids must be FILL or HOLES; got {voids!r}")
    if not (np.isfinite(unit_metres) and unit_metres > 0):
        raise InvalidInputError(f"The unit scale must be positive; got {unit_metres!r}")
    geo = open_geotiffs(paths)
    names = ", ".join(os.path.basename(i.path) for i in geo.files)
    filled = FilledGrid(geo.grid, cut=voids == "HOLES", budget_bytes=budget_bytes, name=names, progress=progress)
    tx, ty = (t / unit_metres for t in geo.texel)
    same = abs(tx - ty) <= GRID_TOLERANCE * tx
    hm = HeightMap(filled, texel_size=tx, texel_size_y=0.0 if same else ty,
                   scale=exaggeration * geo.vertical / unit_metres, source=names)
    return hm, geo

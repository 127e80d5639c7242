"""GeoTIFF files for the tests, the bench and the demo, written with tifffile (an independent, well-kept writer):
known placements, units, no-data values, tiled or striped, compressed."""

import numpy as np
import tifffile

#: GeoKey ids (GeoTIFF 1.1, §6.2) and values.
GT_MODEL, GT_RASTER, GEOGRAPHIC_TYPE, ANGULAR_UNITS = 1024, 1025, 2048, 2054
PROJECTED_CS, LINEAR_UNITS, VERTICAL_UNITS = 3072, 3076, 4099


def write_geotiff(path, top_first, spacing=(30.0, 30.0), corner=(500000.0, 4600000.0), nodata=None, tile=(64, 64),
                  rowsperstrip=None, compression="zlib", geographic=False, point=False, vertical=None, linear=None,
                  transform=None, tiepoints=None, pixel_scale=True, crs=None, predictor=None):
    """Write ``top_first`` (H, W) as a GeoTIFF: ``corner`` is the model position of the top-left pixel's corner
    (PixelIsArea) or of its sample (``point``); ``transform``: a 4x4 ModelTransformation instead of scale and tie
    point; ``tiepoints``: the raw tie point list; ``tile=None`` writes strips of ``rowsperstrip`` rows."""
    keys = [(GT_MODEL, 2 if geographic else 1), (GT_RASTER, 2 if point else 1)]
    if geographic:
        keys += [(GEOGRAPHIC_TYPE, crs or 4326), (ANGULAR_UNITS, 9102)]
    else:
        keys.append((PROJECTED_CS, crs or 32633))
    if linear is not None:
        keys.append((LINEAR_UNITS, linear))
    if vertical is not None:
        keys.append((VERTICAL_UNITS, vertical))
    keys.sort()
    directory = [1, 1, 0, len(keys)] + [v for k, value in keys for v in (k, 0, 1, value)]
    extratags = [(34735, "H", len(directory), directory, True)]
    if transform is not None:
        extratags.append((34264, "d", 16, tuple(float(v) for v in np.ravel(transform)), True))
    else:
        if pixel_scale:
            extratags.append((33550, "d", 3, (float(spacing[0]), float(spacing[1]), 0.0), True))
        tie = tiepoints if tiepoints is not None else (0.0, 0.0, 0.0, corner[0], corner[1], 0.0)
        extratags.append((33922, "d", len(tie), tuple(float(v) for v in tie), True))
    if nodata is not None:
        extratags.append((42113, "s", 0, str(nodata), True))
    kw = dict(tile=tile) if tile is not None else dict(rowsperstrip=rowsperstrip or 16)
    if predictor is not None:
        kw["predictor"] = predictor
    tifffile.imwrite(path, np.ascontiguousarray(top_first), compression=compression, extratags=extratags,
                     photometric="minisblack", metadata=None, **kw)
    return path

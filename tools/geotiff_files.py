"""Elevation files for the tests, the bench and the demo, from heights the caller knows: GeoTIFFs written with
tifffile (an independent, well-kept writer; known tags, tiled or striped, compressed) and rasters of every kind
written by GDAL itself through rasterio (`write_raster`: the files GIS tools give users)."""

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


def write_raster(path, top_first, spacing=(30.0, 30.0), corner=(500000.0, 4600000.0), crs="EPSG:32633",
                 driver="GTiff", nodata=None, scale=None, offset=None, mask=None, units=None, point=False,
                 transform=None, internal_mask=True, **creation):
    """Write ``top_first`` ((H, W), or (count, H, W)) with GDAL itself (rasterio): any driver GDAL can create or
    copy to (GTiff, COG, SRTMHGT, AAIGrid, HFA...), a no-data value, the band's ``scale`` and ``offset``, a
    ``mask`` ((H, W) bool, True valid) as GDAL's mask band (internal, or a ``.msk`` file beside it with
    ``internal_mask=False``), the band's ``units``, ``point`` for
    PixelIsPoint; ``corner`` is the top-left pixel's corner (its sample for ``point``); ``transform`` a
    rasterio `Affine` instead; ``creation`` GDAL creation options (COMPRESS="ZSTD", TILED=True, BIGTIFF="YES"...)."""
    import rasterio
    from rasterio.transform import from_origin

    data = np.asarray(top_first)
    bands = data if data.ndim == 3 else data[None]
    if transform is None:
        x, y = corner
        if point:  # GDAL stores PixelIsPoint by moving its corner-based transform by half a sample
            x, y = x - 0.5 * spacing[0], y + 0.5 * spacing[1]
        transform = from_origin(x, y, spacing[0], spacing[1])
    profile = dict(width=bands.shape[2], height=bands.shape[1], count=bands.shape[0], dtype=bands.dtype.name,
                   crs=crs, transform=transform, nodata=nodata, **creation)
    copy_only = driver not in ("GTiff", "HFA", "ENVI")

    def fill(ds):
        ds.write(bands)
        if point:
            ds.update_tags(AREA_OR_POINT="Point")
        if scale is not None or offset is not None:
            ds.scales = (scale or 1.0,) * bands.shape[0]
            ds.offsets = (offset or 0.0,) * bands.shape[0]
        if units is not None:
            ds.units = (units,) * bands.shape[0]
        if mask is not None:
            ds.write_mask(np.where(mask, 255, 0).astype(np.uint8))

    with rasterio.Env(GDAL_TIFF_INTERNAL_MASK=internal_mask):
        if not copy_only:
            with rasterio.open(path, "w", driver=driver, **profile) as ds:
                fill(ds)
            return path
        import rasterio.shutil

        staged = path + ".staging.tif"
        with rasterio.open(staged, "w", driver="GTiff", **{k: v for k, v in profile.items()
                                                             if k not in creation}) as ds:
            fill(ds)
        try:
            rasterio.shutil.copy(staged, path, driver=driver, **creation)
        finally:
            rasterio.shutil.delete(staged)
    return path

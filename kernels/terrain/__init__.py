"""Adaptive terrain level of detail from height maps, crack-free and screen-space error bounded.

[Nunes 2011, §5] (terrain rendering by local parallel processing: the height-acceleration map, T_min/T_max,
§5.4-5.6). `heightmap_io` reads 8/16-bit, float and raw height maps; `geotiff` places elevation files (units,
several files on one grid), read through GDAL by `gdal_raster` or from their TIFF tags, their samples a block at a
time (`sample_grid`), their voids filled or cut (`void_fill`); `analysis` builds the per-tile table
(``terrain_ham.cl`` through `opencl_path`), `lod` selects levels for a camera, `mesh` bakes the selection,
`synth` makes test terrains.
"""

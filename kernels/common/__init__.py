"""Shared kernel pieces: `errors` (the `TesseraError` family), `tolerances` (every numeric tolerance),
`workers` (threads for independent parts), `opencl_runtime` (context, programs, the numpy fallback), `mesh_arrays`
(a triangle mesh as arrays), `topology` (edges, ragged ranges), `camera` (view, projection, viewport),
`partition` (levels to segment counts and point parameters, the fixed-function tessellator's spacing, used by
tessellation and terrain) and `image_io` (OpenImageIO reads and atomic writes, used by terrain and maps).
"""

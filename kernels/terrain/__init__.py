"""Adaptive terrain level of detail from height maps, crack-free and screen-space error bounded.

[Nunes 2011, §5] (terrain rendering by local parallel processing: the height-acceleration map, T_min/T_max,
§5.4-5.6). `heightmap_io` reads 8/16-bit, float and raw height maps, `analysis` builds the per-tile table
(``terrain_ham.cl`` through `opencl_path`), `lod` selects levels for a camera, `mesh` bakes the selection,
`synth` makes test terrains.
"""

"""Tubes around curves, hair strands and wire meshes.

[Nunes 2011, §4] (tubes from discrete curves: rotation-minimising frames, continuous level of detail, the
anti-aliasing clamp, eq. 4-2 to 4-8). `polylines` is the curve container, `curve_refine` the Catmull-Rom
refinement and point selection, `edge_chains` turns wire meshes into curves, `frames` the double-reflection
frames (``tube_frames.cl``), `caps` the flat and round caps, `builder` the mesh (``tube_body.cl`` through
`opencl_path`).
"""

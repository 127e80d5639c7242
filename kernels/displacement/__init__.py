"""Displacement maps and the brushes that edit them.

[Andrade 2012, ch. 5] (the extensible architecture: dabs, brushes, custom kernels) and what an implementation
reproduces). `map_dabs` is the numpy reference of every kernel of ``map_dabs.cl``, `map_edit` plans and runs
edits on either backend, `map_buffer` keeps a map on the OpenCL device, `map_strokes` turns strokes into dabs
with tile undo, `map_io` reads and writes map files, `tangent_space` is the MikkTSpace frame of tangent maps.
"""

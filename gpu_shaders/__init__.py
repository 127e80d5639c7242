"""GLSL sources (files) and the Python that declares, compiles (lazily, cached) and draws them.

Shared here: `loader` (GLSL files by path, compiled shaders), `offscreen` (offscreen renders, the flat mesh
shader), `textures`, ``partition.glsl`` (the tessellator's spacing, for tessellation and terrain). One
subpackage per capability holds its ``*.glsl`` beside its `draw` module.
"""

"""Pure compute for Tessera: numpy references and OpenCL kernels.

Nothing in this package imports Blender (`bpy`, `gpu`, `mathutils`, `bmesh`); a test enforces it.
Every other path (GPU shaders, geometry nodes, OpenCL) is checked against the functions here.
"""

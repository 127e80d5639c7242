"""Pure compute for Tessera: numpy references and OpenCL kernels, one subpackage per capability.

``common/`` holds what several capabilities share; every other subpackage holds one capability, every ``.cl`` file
beside the Python that runs it (the module map: ``docs/architecture.md``).
Nothing in this package imports Blender (`bpy`, `gpu`, `mathutils`, `bmesh`); a test enforces it.
Every other path (GPU shaders, geometry nodes, OpenCL) is checked against the functions here.
"""

"""Pure compute for Tessera: numpy references and OpenCL kernels, one subpackage per capability.

``common/`` holds what several capabilities share (errors, tolerances, worker threads, the OpenCL runtime, mesh
arrays, topology, the camera, the tessellator's edge partition, image I/O); ``tessellation/``, ``tubes/``,
``terrain/`` and ``displacement/`` hold one capability each, every ``.cl`` file beside the Python that runs it.
Nothing in this package imports Blender (`bpy`, `gpu`, `mathutils`, `bmesh`); a test enforces it.
Every other path (GPU shaders, geometry nodes, OpenCL) is checked against the functions here.
"""

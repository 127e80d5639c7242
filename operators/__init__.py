"""Blender operators, one module per capability; thin wrappers over `kernels`."""

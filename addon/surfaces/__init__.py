"""Surfaces in Blender: the parametric-surface settings (`settings`) shared by ``tessera.parametric_surface_add``."""

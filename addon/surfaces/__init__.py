"""Surfaces in Blender: parametric surfaces, Tessellate Surface and adaptive curves (their settings, previews, panels,
the control points they read)."""

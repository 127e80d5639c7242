"""Curve and patch geometry the capabilities share: rational Bézier pieces, NURBS as Blender holds them, steps
spaced where a curve bends, and adaptive curve sampling."""

"""Displacement maps in Blender ([Andrade 2012]): their settings and brush, the maps' state and undo, the tangent-space
node group and the viewport brush tool."""

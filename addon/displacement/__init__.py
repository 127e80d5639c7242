"""Displacement maps in Blender ([Andrade 2012]): `settings` (``Object.tessera.displacement`` and the brush on
``Scene.tessera.brush``), `maps` (map state, undo, the modifier that shows a map), `nodes` (the tangent-space
node group), `brush_cursor` and `brush_tool` (the viewport tool) and `panel`."""

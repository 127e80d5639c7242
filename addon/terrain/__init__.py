"""Terrain in Blender: `settings` (``Object.tessera.terrain``), `data` (height maps and analyses cached per
object, the baked mesh), `preview` (the live GPU preview, [Nunes 2011, §5]) and `panel`."""

"""Tubes in Blender: `settings` (``Object.tessera.tubes``), `sources` (curves, hair and wire meshes read as
polylines), `preview` (the live GPU preview, [Nunes 2011, §4]) and `panel`."""

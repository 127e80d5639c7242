"""Tubes in Blender: `settings` (``Object.tessera.tubes``), `sources` (curves, hair and wire meshes read as
polylines), `preview` (the live GPU preview, seed 000 §4) and `panel`."""

"""Tessellation in Blender: `settings` (the options shared by the operator and ``Object.tessera.tessellate``),
`preview` (the live GPU preview, [Nellmedin 2014, §5] done with instanced patterns) and `panel`."""

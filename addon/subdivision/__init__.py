"""Loop subdivision in Blender: `panel` (Tessera > Loop Subdivision); the operator is
``operators/subdivision.py``."""

"""Loop subdivision in Blender: its settings, preview and panel, the mesh it builds and the Cycles bake of its light
(the operators: ``operators/subdivision.py``)."""

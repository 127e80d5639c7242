"""Tubes around curves, hair strands and wire meshes ([Nunes 2011, §4]). The module map: ``docs/architecture.md``."""

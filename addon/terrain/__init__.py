"""Terrain in Blender ([Nunes 2011, §5]): its settings, the height maps and analyses cached per object, the live GPU
preview, the panel and the Terrain node group."""

"""Tubes in Blender ([Nunes 2011, §4]): their settings, the curves, hair and wire meshes read as polylines, the live
GPU preview, the panel and the Tubes node group."""

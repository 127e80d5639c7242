"""Nailboards and impostors in Blender: their settings, the live board, the Cycles workers that render boards and
atlases, the baked card and its glTF export."""

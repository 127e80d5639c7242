"""Blender glue, one subpackage per capability.

Shared here: `preferences`, `properties` (the ``tessera`` pointers on Object, Scene and Image), `bridge` (the one
place where mesh and pixel data cross the bpy boundary), `gpu_context`, `viewport` (draw handlers, preview
caches and the invalidation that settings send to previews), `cameras`, `menus`, `sidebar` (the panel base).
Each capability package (``tessellation``, ``tubes``, ``terrain``, ``displacement``) holds its settings, its
viewport preview, its panel and its tools.
"""

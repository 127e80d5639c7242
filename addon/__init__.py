"""Blender glue: preferences, menus, the mesh<->numpy bridge and the GPU-context helper."""

"""Blender glue: one subpackage per capability (its settings, preview, panel and tools) and what they share
(preferences, the bpy bridge, previews, menus, the command line). The module map: ``docs/architecture.md``."""

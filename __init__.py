"""Tessera: generate geometry where artists need it (Blender extension entry point).

Registration only: submodules are registered in the order below and unregistered in reverse.
Nothing is computed or compiled at import or register time.
"""

import importlib

_modules = (
    "addon.preferences",
    "addon.tube_settings",
    "addon.displacement_settings",
    "addon.terrain_settings",
    "addon.settings",
    "addon.displacement_maps",
    "operators.tessellate",
    "operators.tubes",
    "operators.displacement",
    "operators.custom_kernel",
    "operators.terrain",
    "addon.menus",
    "addon.panels",
    "addon.tube_preview",
    "addon.terrain_preview",
    "addon.patch_preview",
    "addon.brush_cursor",
    "addon.brush_tool",
)


def register():
    for name in _modules:
        importlib.import_module(f".{name}", __package__).register()


def unregister():
    for name in reversed(_modules):
        importlib.import_module(f".{name}", __package__).unregister()

"""Tessera: generate geometry where artists need it (Blender extension entry point).

Registration only: submodules are registered in the order below and unregistered in reverse. `addon.properties`
registers every capability's settings and the ``tessera`` pointers; panels register in the sidebar's order.
Nothing is computed or compiled at import or register time (`addon.opencl_warmup` only schedules its thread).
"""

import importlib

_modules = (
    "addon.viewport",
    "addon.preferences",
    "addon.opencl_warmup",
    "addon.render_jobs",
    "addon.properties",
    "addon.displacement.maps",
    "operators.tessellation",
    "operators.tubes",
    "operators.displacement",
    "operators.custom_kernel",
    "operators.terrain",
    "operators.subdivision",
    "operators.surfaces",
    "operators.vector_field",
    "operators.impostors",
    "operators.node_groups",
    "addon.node_library",
    "addon.menus",
    "addon.start_panel",
    "addon.tessellation.panel",
    "addon.tubes.panel",
    "addon.displacement.panel",
    "addon.terrain.panel",
    "addon.subdivision.panel",
    "addon.node_panel",
    "addon.surfaces.panel",
    "addon.impostors.panel",
    "addon.tubes.preview",
    "addon.terrain.preview",
    "addon.tessellation.preview",
    "addon.subdivision.preview",
    "addon.surfaces.preview",
    "addon.impostors.preview",
    "addon.displacement.brush_cursor",
    "addon.displacement.brush_tool",
    "addon.command_line",
)


def register():
    for name in _modules:
        importlib.import_module(f".{name}", __package__).register()


def unregister():
    for name in reversed(_modules):
        importlib.import_module(f".{name}", __package__).unregister()

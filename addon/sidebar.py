"""The base of Tessera's sidebar panels (View3D > Sidebar > Tessera); each capability's ``panel`` module
subclasses it."""


class Sidebar:
    """Where Tessera's panels live: View3D > Sidebar > Tessera. Shown for active objects of ``object_types``."""

    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Tessera"
    object_types = frozenset({"MESH"})

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        return ob is not None and ob.type in cls.object_types

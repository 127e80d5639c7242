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
        ob = active_object(context)
        return ob is not None and ob.type in cls.object_types


def active_object(context):
    """The view layer's active object, hidden or not: a hidden object keeps its panels (its preview and settings stay
    reachable), where ``context.active_object`` is None."""
    view_layer = getattr(context, "view_layer", None)
    return view_layer.objects.active if view_layer is not None else context.active_object

"""The base of Tessera's sidebar panels (View3D > Sidebar > Tessera); each capability's ``panel`` module
subclasses it."""


#: The order of Tessera's sidebar panels, top first: what an object *is* (a terrain, a live surface, a curve for
#: tubes) before what can be done to any mesh; each panel's ``bl_order`` is its place here (`panel_order`).
PANEL_ORDER = ("TESSERA_PT_gpu_notice", "TESSERA_PT_terrain", "TESSERA_PT_surfaces", "TESSERA_PT_tubes",
               "TESSERA_PT_tessellation", "TESSERA_PT_displacement", "TESSERA_PT_subdivision", "TESSERA_PT_impostors",
               "TESSERA_PT_node_groups", "TESSERA_PT_start")


def panel_order(idname):
    """``bl_order`` of the panel ``idname``: its place in `PANEL_ORDER`."""
    return PANEL_ORDER.index(idname)


def wrapped_label(layout, context, text, icon="NONE"):
    """``text`` as labels wrapped to the region's width (a sidebar at Blender's default width shows about 35
    characters), the icon on the first line only: no hint is clipped."""
    import textwrap

    region = getattr(context, "region", None)
    scale = (context.preferences.system.ui_scale if getattr(context, "preferences", None) else 0.0) or 1.0
    width = max(20, int((region.width if region is not None else 300) / (7.0 * scale)) - 4)
    col = layout.column(align=True)
    for i, line in enumerate(textwrap.wrap(text, width) or [""]):
        col.label(text=line, icon=icon if i == 0 else "BLANK1" if icon != "NONE" else "NONE")
    return col


def preview_notice(layout, context, on, how):
    """Under a preview switched ``on`` where the viewport shades in Material Preview or Rendered: the preview is drawn
    as in Solid mode there, its object is left out of the viewport's render while it is on, and F12 renders the
    object as it is; ``how`` (a phrase) says how to get the result into a render."""
    shading = getattr(getattr(getattr(context, "space_data", None), "shading", None), "type", "SOLID")
    if on and shading in {"MATERIAL", "RENDERED"}:
        wrapped_label(layout.box(), context, "Live Preview is drawn as in Solid mode; renders show the object without "
                      f"it. To render the result, {how}.", icon="INFO")


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

"""The displacement brush as a 3D Viewport tool (Object Mode): drag to paint the active object's map;
F and Shift+F change radius and strength as in Sculpt Mode."""

import bpy


def draw_brush_settings(layout, brush, channels=1):
    layout.use_property_split = True
    layout.use_property_decorate = False
    layout.prop(brush, "kind")
    layout.prop(brush, "radius")
    layout.prop(brush, "strength")
    if brush.kind in {"DRAW", "SMOOTH", "FLATTEN", "NOISE"}:
        layout.prop(brush, "falloff")
    if brush.kind == "NOISE":
        layout.prop(brush, "noise_cell")
        layout.prop(brush, "noise_seed")
    if channels > 1 and brush.kind in {"DRAW", "NOISE", "TEST"}:
        layout.prop(brush, "direction")
    layout.prop(brush, "spacing")
    col = layout.column(heading="Pressure")
    col.prop(brush, "use_pressure_strength", text="Strength")
    col.prop(brush, "use_pressure_radius", text="Radius")
    layout.prop(brush, "mirror_x")


def map_channels(context):
    """Channels of the active object's displacement map: 1 (height) or 3 (vector)."""
    ob = context.active_object
    return 3 if ob is not None and ob.type == "MESH" and ob.tessera.displacement.mode == "VECTOR" else 1


def draw_brush_header(layout, brush):
    """The tool header, as Sculpt Mode's: the brush, radius and strength each with its pen-pressure toggle, and the
    other settings in a popover."""
    layout.prop(brush, "kind", text="")
    row = layout.row(align=True)
    row.prop(brush, "radius")
    row.prop(brush, "use_pressure_radius", text="", icon="STYLUS_PRESSURE")
    row = layout.row(align=True)
    row.prop(brush, "strength")
    row.prop(brush, "use_pressure_strength", text="", icon="STYLUS_PRESSURE")
    layout.popover("TESSERA_PT_brush_more", text="", icon="PREFERENCES")


class TESSERA_PT_brush_more(bpy.types.Panel):
    """The brush settings the header has no room for (a popover of the tool header)."""

    bl_space_type = "VIEW_3D"
    bl_region_type = "HEADER"
    bl_label = "Brush"
    bl_idname = "TESSERA_PT_brush_more"

    @classmethod
    def poll(cls, context):
        ob = context.active_object
        return ob is not None and ob.type == "MESH" and ob.tessera.displacement.image is not None

    def draw(self, context):
        draw_brush_settings(self.layout.column(), context.scene.tessera.brush, map_channels(context))


class TESSERA_TL_displacement_brush(bpy.types.WorkSpaceTool):
    bl_space_type = "VIEW_3D"
    bl_context_mode = "OBJECT"
    bl_idname = "tessera.displacement_brush"
    bl_label = "Displacement Brush"
    bl_description = "Paint the active object's displacement map (Tessera)"
    bl_icon = "brush.sculpt.displacement_smear"  # in every supported Blender (4.2 to 5.2)
    bl_widget = "TESSERA_GGT_brush_cursor"  # the ring follows the mouse before and between strokes
    bl_keymap = (
        ("tessera.displacement_stroke", {"type": "LEFTMOUSE", "value": "PRESS"}, None),
        ("wm.radial_control", {"type": "F", "value": "PRESS"},
         {"properties": [("data_path_primary", "scene.tessera.brush.radius")]}),
        ("wm.radial_control", {"type": "F", "value": "PRESS", "shift": True},
         {"properties": [("data_path_primary", "scene.tessera.brush.strength")]}),
    )

    def draw_settings(context, layout, tool):
        brush = context.scene.tessera.brush
        if getattr(context.region, "type", "") == "TOOL_HEADER":
            draw_brush_header(layout, brush)
        else:
            draw_brush_settings(layout.column(), brush, map_channels(context))


def register():
    bpy.utils.register_class(TESSERA_PT_brush_more)
    bpy.utils.register_tool(TESSERA_TL_displacement_brush, separator=True)


def unregister():
    bpy.utils.unregister_tool(TESSERA_TL_displacement_brush)
    bpy.utils.unregister_class(TESSERA_PT_brush_more)

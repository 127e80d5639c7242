"""No sidebar panel shows two rows with the same label in one section (Tubes once had two called "Sides"), and no
label is cut short at Blender's default sidebar width ("Segment Spac..."): every panel is drawn into a layout that
records its rows, for an object of each kind."""

from types import SimpleNamespace

import numpy as np
import pytest
from conftest import Recorder

pytestmark = pytest.mark.blender


#: The widest label the sidebar's label column shows whole at its default width and UI scale 1, in pixels of
#: Blender's interface font at 11 px (measured in the real window: "Angle Tolerance", 86 px, fits; "Segment Spacing",
#: 93 px, is cut to "Segment Spac...").
LABEL_COLUMN_PX = 88


def _drawn(bpy, addon_module):
    """{panel bl_idname: the labels of its rows} for the panels the active object gets; the labels of the rows that
    are not check boxes (a check box's label stands in the wider value column) are checked against the label
    column's width."""
    import blf

    sidebar = addon_module("addon.sidebar")
    out = {}
    for idname in sidebar.PANEL_ORDER:
        panel = getattr(bpy.types, idname, None)
        if panel is None or not panel.poll(bpy.context):
            continue
        rows, fields = [], []
        context = SimpleNamespace(**{k: getattr(bpy.context, k) for k in ("view_layer", "scene", "active_object",
                                                                          "preferences", "window_manager")},
                                  space_data=None, region=SimpleNamespace(width=240))
        panel.draw(SimpleNamespace(layout=Recorder(rows, fields=fields)), context)
        out[idname] = rows
        blf.size(0, 11)
        cut = [label for label, kind in fields if kind != "BOOLEAN" and blf.dimensions(0, label)[0] > LABEL_COLUMN_PX]
        assert not cut, f"{idname}: labels cut short in the sidebar: {cut}"
    return out


def _no_repeats(drawn):
    repeated = {idname: sorted({r for r in rows if rows.count(r) > 1}) for idname, rows in drawn.items()}
    assert drawn and not any(repeated.values()), repeated


def test_mesh_panels_have_no_repeated_label(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    bpy.ops.mesh.primitive_monkey_add()
    assert bpy.ops.tessera.displacement_add(width=16, height=16) == {"FINISHED"}
    _no_repeats(_drawn(bpy, addon_module))


def test_curve_terrain_and_surface_panels_have_no_repeated_label(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    bpy.ops.curve.primitive_bezier_circle_add()
    for sides in ("FIXED", "CAMERA"):
        bpy.context.active_object.tessera.tubes.sides_mode = sides
        drawn = _drawn(bpy, addon_module)
        assert "TESSERA_PT_tubes" in drawn
        _no_repeats(drawn)
    image = bpy.data.images.new("Hills", 17, 17, float_buffer=True)
    image.pixels.foreach_set(np.random.default_rng(2).random(17 * 17 * 4).astype(np.float32))
    assert bpy.ops.tessera.terrain_add(source="IMAGE", image_name=image.name) == {"FINISHED"}
    _no_repeats(_drawn(bpy, addon_module))
    assert bpy.ops.tessera.parametric_surface_add(output="LIVE") == {"FINISHED"}
    _no_repeats(_drawn(bpy, addon_module))
    bpy.data.images.remove(image)

"""No sidebar panel shows two rows with the same label in one section (Tubes once had two called "Sides"): every
panel is drawn into a layout that records its rows, for an object of each kind."""

from types import SimpleNamespace

import numpy as np
import pytest
from conftest import Recorder

pytestmark = pytest.mark.blender


def _drawn(bpy, addon_module):
    """{panel bl_idname: the labels of its rows} for the panels the active object gets."""
    sidebar = addon_module("addon.sidebar")
    out = {}
    for idname in sidebar.PANEL_ORDER:
        panel = getattr(bpy.types, idname, None)
        if panel is None or not panel.poll(bpy.context):
            continue
        rows = []
        context = SimpleNamespace(**{k: getattr(bpy.context, k) for k in ("view_layer", "scene", "active_object",
                                                                          "preferences", "window_manager")},
                                  space_data=None, region=SimpleNamespace(width=240))
        panel.draw(SimpleNamespace(layout=Recorder(rows)), context)
        out[idname] = rows
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

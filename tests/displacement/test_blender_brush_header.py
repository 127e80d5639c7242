"""The displacement brush's tool header, as Sculpt Mode's: the brush, Radius and Strength each with its
pen-pressure toggle, the rest in a popover; the properties editor's tool tab gets every setting."""

from types import SimpleNamespace

import pytest
from conftest import Recorder

pytestmark = pytest.mark.blender


def _drawn(bpy, addon_module, region_type):
    tool = addon_module("addon.displacement.brush_tool").TESSERA_TL_displacement_brush
    rows, popovers = [], []
    layout = Recorder(rows)
    layout.popover = lambda panel, **kwargs: popovers.append(panel)
    context = SimpleNamespace(scene=bpy.context.scene, active_object=bpy.context.active_object,
                              region=SimpleNamespace(type=region_type))
    tool.draw_settings(context, layout, None)
    return rows, popovers


def test_the_header_holds_radius_strength_and_pressure(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    bpy.ops.mesh.primitive_grid_add()
    assert bpy.ops.tessera.displacement_add(width=16, height=16) == {"FINISHED"}
    rows, popovers = _drawn(bpy, addon_module, "TOOL_HEADER")
    brush = bpy.context.scene.tessera.brush.bl_rna.properties
    assert [brush[n].name for n in ("radius", "strength")] == [r for r in rows if r in ("Radius", "Strength")]
    assert len(rows) == 2, rows  # the brush kind and the pressure toggles draw without text
    assert popovers == ["TESSERA_PT_brush_more"]
    full, _ = _drawn(bpy, addon_module, "WINDOW")
    assert {"Radius", "Strength", "Spacing", "Pressure: Strength", "Pressure: Radius"} <= set(full)

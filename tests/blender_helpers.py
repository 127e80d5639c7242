"""Helpers shared by the blender-tier tests (importable as ``blender_helpers``, like ``mesh_checks``)."""

import importlib

import pytest
from conftest import ADDON_MODULE


def select_only(bpy, *obs):
    """Select exactly ``obs`` and make the first one active (what a click and shift-clicks leave)."""
    for other in bpy.context.selected_objects:
        other.select_set(False)
    for ob in obs:
        ob.select_set(True)
    bpy.context.view_layer.objects.active = obs[0]


def compat():
    """The enabled add-on's `addon.compat` (what differs between Blender versions)."""
    return importlib.import_module(f"{ADDON_MODULE}.addon.compat")


def refuses_tangent_space(bpy, size=32):
    """On a Blender without the UV Tangent node, a tangent-space map is refused with the version it needs and
    nothing is made."""
    message = compat().UV_TANGENT_MESSAGE
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=4, y_subdivisions=4, size=2)
    images = len(bpy.data.images)
    with pytest.raises(RuntimeError) as err:
        bpy.ops.tessera.displacement_add(width=size, height=size, mode="VECTOR", space="TANGENT")
    assert message in str(err.value)
    assert len(bpy.data.images) == images and not bpy.context.active_object.modifiers


def stroke_elements(points, map_space=True):
    """Stroke elements for ``tessera.displacement_stroke`` from map texels (x, y, pressure) or surface points
    (x, y, z), each with every field this Blender's stroke element needs."""
    element = compat().stroke_element
    return [element(p[:3] if not map_space else (p[0], p[1], 0.0), p[2] if map_space else 1.0, first=i == 0)
            for i, p in enumerate(points)]

"""The sidebar shows an object the panels of what it is, in the order of `sidebar.PANEL_ORDER`: a terrain its
Terrain panel first, a curve its Tubes panel first, a plain mesh the mesh tools and no Tubes, a wire mesh Tubes."""

import numpy as np
import pytest

pytestmark = pytest.mark.blender


class LabelLayout:
    """A stand-in for a panel's layout that keeps the text of each label drawn into it (boxes and columns: itself)."""

    def __init__(self):
        self.labels = []

    def box(self):
        return self

    def column(self, align=False):
        return self

    def label(self, text="", icon="NONE"):
        self.labels.append(text)


def shown(bpy, addon_module):
    """The bl_labels of the Tessera panels the active object gets, top first."""
    sidebar = addon_module("addon.sidebar")
    panels = [getattr(bpy.types, idname) for idname in sidebar.PANEL_ORDER if hasattr(bpy.types, idname)]
    visible = [p for p in panels if p.poll(bpy.context)]
    assert [p.bl_order for p in visible] == sorted(p.bl_order for p in visible)
    return [p.bl_label for p in sorted(visible, key=lambda p: p.bl_order)]


def test_a_plain_mesh_gets_the_mesh_tools_and_no_tubes(clean_scene, bpy_module, addon_module):
    bpy_module.ops.mesh.primitive_monkey_add()
    labels = shown(bpy_module, addon_module)
    assert labels[0] == "Tessellate" and "Tubes" not in labels and "Terrain" not in labels
    assert {"Loop Subdivision", "Displacement Map", "Impostors"} <= set(labels)


def test_a_wire_mesh_and_a_curve_get_tubes_first(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    mesh = bpy.data.meshes.new("Wire")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (1, 1, 0)], [(0, 1), (1, 2)], [])
    ob = bpy.data.objects.new("Wire", mesh)
    bpy.context.collection.objects.link(ob)
    bpy.context.view_layer.objects.active = ob
    assert shown(bpy, addon_module)[0] == "Tubes"
    bpy.ops.curve.primitive_bezier_curve_add()
    assert shown(bpy, addon_module)[0] == "Tubes"


def test_a_terrain_gets_its_terrain_panel_first(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    image = bpy.data.images.new("Hills", 33, 33, float_buffer=True)
    image.pixels.foreach_set(np.random.default_rng(1).random(33 * 33 * 4).astype(np.float32))
    assert bpy.ops.tessera.terrain_add(source="IMAGE", image_name=image.name) == {"FINISHED"}
    labels = shown(bpy, addon_module)
    assert labels[0] == "Terrain" and "Tubes" not in labels
    bpy.data.images.remove(image)


def test_nothing_fitting_gets_start_here_only(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    bpy.ops.object.camera_add()
    assert shown(bpy, addon_module) == ["Start Here"]


def test_material_preview_and_rendered_say_how_to_render_the_result(clean_scene, bpy_module, addon_module):
    """In Material Preview and Rendered shading a preview that is on says it is drawn as in Solid mode, and how to
    get its result into a render; in Solid mode, or with the preview off, nothing is said."""
    from types import SimpleNamespace

    sidebar = addon_module("addon.sidebar")

    def said(shading, on):
        layout = LabelLayout()
        context = SimpleNamespace(space_data=SimpleNamespace(shading=SimpleNamespace(type=shading)),
                                  region=SimpleNamespace(width=320), preferences=bpy_module.context.preferences)
        sidebar.preview_notice(layout, context, on, "apply it (Tessellate)")
        return " ".join(layout.labels)

    assert "apply it (Tessellate)" in said("MATERIAL", True) and "Solid" in said("RENDERED", True)
    assert said("SOLID", True) == "" and said("RENDERED", False) == ""


def test_the_impostors_panel_says_when_this_blender_has_no_denoiser(bpy_module, addon_module, monkeypatch):
    """A Blender whose Cycles lacks OpenImageDenoise (some distributions' builds) renders grainy boards and cards: the
    Impostors panel says so and what to raise; with the denoiser it says nothing."""
    from types import SimpleNamespace

    compat, panel = addon_module("addon.compat"), addon_module("addon.impostors.panel")
    import _cycles

    assert compat.has_denoiser() == bool(getattr(_cycles, "with_openimagedenoise", False))

    def said(has):
        monkeypatch.setattr(compat, "has_denoiser", lambda: has)
        layout = LabelLayout()
        panel.denoiser_notice(layout, SimpleNamespace(region=SimpleNamespace(width=320),
                                                      preferences=bpy_module.context.preferences))
        return " ".join(layout.labels)

    assert "no denoiser" in said(False) and "Samples" in said(False)
    assert said(True) == ""

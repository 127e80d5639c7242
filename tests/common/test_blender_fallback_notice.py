"""Without an OpenCL device the add-on computes with numpy, and says so where a window shows it: the first operator
after the fallback reports a warning (the status bar), once (tier: blender)."""

import pytest

pytestmark = pytest.mark.blender


def test_the_first_operator_after_the_fallback_warns_once(clean_scene, bpy_module, addon_module, capfd, monkeypatch):
    bpy = bpy_module
    runtime = addon_module("kernels.common.opencl_runtime")
    errors = addon_module("kernels.common.errors")

    def missing():
        raise errors.OpenCLUnavailableError("simulated: no OpenCL platform")

    monkeypatch.setattr(runtime, "_create", missing)
    runtime.configure(mode="1")
    try:
        with pytest.warns(RuntimeWarning):
            runtime.get_runtime()  # what the warm-up or a kernel does first
        capfd.readouterr()
        bpy.ops.mesh.primitive_cube_add()
        assert bpy.ops.tessera.tessellate(level=2) == {"FINISHED"}
        first = capfd.readouterr().out
        bpy.ops.mesh.primitive_cube_add()
        assert bpy.ops.tessera.tessellate(level=2) == {"FINISHED"}
        second = capfd.readouterr().out
    finally:
        monkeypatch.undo()
        prefs = bpy.context.preferences.addons[addon_module("addon.preferences").BASE_PACKAGE].preferences
        addon_module("addon.preferences").apply_opencl_settings(prefs)
    assert "No OpenCL device was found, so Tessera computes with numpy" in first
    assert "No OpenCL device" not in second

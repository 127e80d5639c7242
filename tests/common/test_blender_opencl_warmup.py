"""The add-on's OpenCL warm-up (`addon.opencl_warmup`): scheduled in the UI only, a thread that makes the runtime and
builds every shipped program, stopped and waited for when the add-on is disabled."""

import pytest

pytestmark = [pytest.mark.blender, pytest.mark.opencl]


def test_warm_up_thread_builds_every_program_and_is_waited_for(bpy_module, addon_module, addon_opencl):
    warmup = addon_module("addon.opencl_warmup")
    runtime_module = addon_module("kernels.common.opencl_runtime")
    preferences = addon_module("addon.preferences")
    # background mode: no event loop to fire a timer, so registration scheduled nothing
    assert bpy_module.app.background and not bpy_module.app.timers.is_registered(warmup._timer)
    runtime_module.configure(mode="require")
    try:
        thread = warmup.start()
        assert thread is not None and thread.name == "tessera-opencl-warm-up"
        assert warmup.start() is None or not thread.is_alive()  # never two at once
        thread.join(60)
        assert not thread.is_alive()
        warmup.wait()  # what disabling the add-on does: nothing left to wait for
        runtime = runtime_module.get_runtime()
        variants = runtime_module.program_variants()
        assert {(name, ()) for name in runtime_module.program_names()} <= set(variants)
        assert set(variants) <= set(runtime._programs)
        runtime_module.configure(mode="require")  # a new runtime; disabling stops the thread between programs
        thread = warmup.start()
        warmup.wait()
        assert not thread.is_alive()
        runtime_module.configure(mode="0")
        assert warmup.start() is None  # OpenCL off: nothing to warm
    finally:
        preferences.apply_opencl_settings(preferences.get_preferences())

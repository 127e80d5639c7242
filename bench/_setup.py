"""What the benches share: the source tree importable as the package ``tessera`` and enabled in Blender the way an
installed extension is (`tools.source_tree`, the one bootstrap), and timing helpers."""

import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))
from source_tree import as_package  # noqa: E402
from source_tree import enable_extension as _enable  # noqa: E402

_FOLDER = None


def import_path():
    global _FOLDER
    if _FOLDER is None:
        _FOLDER = as_package("tessera-bench-")
        os.environ.setdefault("BLENDER_USER_RESOURCES", str(_FOLDER / "blender_user"))
    return _FOLDER


def enable_extension():
    """Enable Tessera in the bpy module; returns the add-on's package name (``bl_ext.tessera_bench.tessera``)."""
    return _enable(import_path(), "tessera_bench")


def best_of(fn, repeat=5):
    """Shortest of ``repeat`` timed calls of ``fn`` (seconds) and the last call's result."""
    best, result = float("inf"), None
    for _ in range(repeat):
        t = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - t)
    return best, result


def timed_operator(bpy, call, count="polygons"):
    """Seconds of ``call()``, an operator call that leaves its new mesh object active, and the size of that mesh (the
    length of its ``count`` collection); the object and mesh are removed afterwards, untimed. Raises unless the
    operator finished."""
    t = time.perf_counter()
    result = call()
    seconds = time.perf_counter() - t
    if result != {"FINISHED"}:
        raise RuntimeError(f"the operator returned {result}")
    new = bpy.context.active_object
    me = new.data
    n = len(getattr(me, count))
    bpy.data.objects.remove(new)
    bpy.data.meshes.remove(me)
    return seconds, n


def seconds(fn, repeat=3):
    """Shortest of ``repeat`` timed calls of ``fn``, in seconds."""
    return best_of(fn, repeat)[0]


def offscreen_frame(box, width, height):
    """A function ``frame(draw)`` that clears the `gpu.types.GPUOffScreen` ``box`` (``width`` x ``height``), calls
    ``draw()`` with a depth test and reads one pixel back, so the timed frame includes the GPU's work."""
    import gpu

    def frame(draw):
        with box.bind():
            fb = gpu.state.active_framebuffer_get()
            fb.clear(color=(0, 0, 0, 1), depth=1.0)
            gpu.state.depth_test_set("LESS_EQUAL")
            gpu.state.depth_mask_set(True)
            draw()
            fb.read_color(width // 2, height // 2, 1, 1, 4, 0, "UBYTE")
            gpu.state.depth_test_set("NONE")

    return frame

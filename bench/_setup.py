"""Make the source tree importable as the package ``tessera`` (a symlink in a temporary folder), and
enable it in Blender the way an installed extension is (a local extension repository on that folder)."""

import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
_FOLDER = None


def import_path():
    global _FOLDER
    if _FOLDER is None:
        _FOLDER = Path(tempfile.mkdtemp(prefix="tessera-bench-"))
        (_FOLDER / "tessera").symlink_to(ROOT, target_is_directory=True)
        sys.path.insert(0, str(_FOLDER))
        from tessera.tools.temp_folders import remove_at_exit

        remove_at_exit(_FOLDER)  # Blender writes its user folder here as it exits
        os.environ.setdefault("BLENDER_USER_RESOURCES", str(_FOLDER / "blender_user"))
    return _FOLDER


def enable_extension():
    """Enable Tessera in the bpy module; returns the add-on's package name (``bl_ext.tessera_bench.tessera``)."""
    folder = import_path()
    import addon_utils
    import bpy

    repos = bpy.context.preferences.extensions.repos
    if "tessera_bench" not in {r.module for r in repos}:
        repos.new(name="tessera_bench", module="tessera_bench", custom_directory=str(folder), source="USER")
    name = "bl_ext.tessera_bench.tessera"
    if addon_utils.enable(name, default_set=True, handle_error=None) is None:
        raise RuntimeError("Tessera failed to enable")
    return name


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

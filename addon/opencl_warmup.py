"""The OpenCL runtime made and the kernels' programs built on a background thread once Blender's window is up.

Without it, the first tubes, brush stroke, terrain, Loop or Tessellate Surface run of a session waits for the device
to be chosen and each of its programs (and their variants: `opencl_runtime.program_variants`) to be built: a
fraction of a second for the context, and for each program longer still after an install or an update, when
pyopencl's cache is cold. Register only schedules the warm-up: a timer starts the thread a second after registration, in
the UI alone (background and `bpy` module runs have no event loop to fire it, and a script's first operator would
only wait for the same work). The build releases the
GIL, so the interface does not stall. A thread still building when the add-on is disabled or Blender quits is
stopped between programs and waited for (a build in flight is finished, never abandoned inside the driver).
"""

import atexit
import threading

import bpy

from ..kernels.common import opencl_runtime
from ..kernels.common.errors import TesseraError

#: seconds after registration before the thread starts (Blender's window is drawn by then)
DELAY = 1.0
#: seconds to wait for a running warm-up when the add-on is disabled or Blender quits
JOIN_TIMEOUT = 60.0

_state = {"thread": None, "stop": threading.Event()}


def start():
    """Start the warm-up thread now, unless OpenCL is off or a warm-up is running: the new thread, or None."""
    thread = _state["thread"]
    if thread is not None and thread.is_alive():
        return None
    try:
        if opencl_runtime.current_mode() == "0":
            return None
    except TesseraError:  # a bad TESSERA_OPENCL: the first real use reports it
        return None
    stop = _state["stop"] = threading.Event()
    thread = threading.Thread(target=opencl_runtime.warm_up, args=(opencl_runtime.program_variants(), stop),
                              name="tessera-opencl-warm-up", daemon=True)
    _state["thread"] = thread
    thread.start()
    return thread


def _timer():
    start()  # None: the timer runs once


def wait(timeout=JOIN_TIMEOUT):
    """Stop a running warm-up after the program it is building and wait for it (at most ``timeout`` seconds)."""
    thread = _state["thread"]
    if thread is None:
        return
    _state["stop"].set()
    thread.join(timeout)
    _state["thread"] = None


def register():
    if not bpy.app.background:
        bpy.app.timers.register(_timer, first_interval=DELAY, persistent=True)
    atexit.register(wait)


def unregister():
    if bpy.app.timers.is_registered(_timer):
        bpy.app.timers.unregister(_timer)
    atexit.unregister(wait)
    wait()

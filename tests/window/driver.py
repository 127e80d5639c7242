"""Runs one window-tier scenario inside a real Blender window (started by ``tools/window_run.sh``).

    blender --enable-event-simulate --python driver.py -- SCENARIO OUT_DIR BACKEND

Enables the add-on from the working tree (a dev extension repository, as the ``blender`` tier does), then drives
``tests/window/scenarios/SCENARIO.py``: its ``run(w)`` is a generator that yields the seconds to wait before its next
step, so the window draws between steps. It starts once the add-on's start-up work is done, unless the scenario sets
``AFTER_STARTUP = False``. ``w`` is a `Window`: the 3D viewport, screenshots of it, injected events,
and ``w.results``, written to ``OUT_DIR/results.json`` with ``"finished": true`` when the scenario ends (or the error
that stopped it). Blender quits afterwards; the test that started it reads the results and ``blender.log``.

Runs on Blender's own Python (the distribution's, e.g. 3.14) with numpy; nothing here may import pytest.
"""

import json
import os
import subprocess
import sys
import time
import traceback
from pathlib import Path

import bpy
import numpy as np

SRC = Path(__file__).resolve().parents[2]
ARGS = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
SCENARIO, OUT, BACKEND = ARGS[0], Path(ARGS[1]), (ARGS[2] if len(ARGS) > 2 else "opengl")
REPO_MODULE = "tessera_window"
ADDON = f"bl_ext.{REPO_MODULE}.tessera"


def enable_addon():
    """The add-on as Blender loads an extension: a dev repository whose ``tessera`` is the working tree."""
    sys.path.insert(0, str(SRC / "tools"))
    from source_tree import as_package, enable_extension

    return sys.modules[enable_extension(as_package("tessera-repo-", root=SRC), REPO_MODULE)]


class Window:
    """The scenario's handle on the window: the largest 3D viewport, screenshots, events, results."""

    def __init__(self):
        self.results = {"scenario": SCENARIO, "backend": BACKEND, "blender": bpy.app.version_string,
                        "python": sys.version.split()[0], "gpu": None, "finished": False}
        self.out = OUT
        self.addon = ADDON

    @property
    def window(self):
        return bpy.context.window_manager.windows[0]

    @property
    def area(self):
        areas = [a for a in self.window.screen.areas if a.type == "VIEW_3D"]
        return max(areas, key=lambda a: a.width * a.height)

    @property
    def region(self):
        return next(r for r in self.area.regions if r.type == "WINDOW")

    @property
    def space(self):
        return self.area.spaces.active

    def context(self):
        """A context override for operators that need the 3D viewport (``with bpy.context.temp_override(**...)``)."""
        return {"window": self.window, "screen": self.window.screen, "area": self.area, "region": self.region}

    def module(self, name):
        """A submodule of the enabled add-on: ``w.module("addon.viewport")``."""
        import importlib

        return importlib.import_module(f"{ADDON}.{name}")

    def redraw(self, iterations=1, area=None):
        """Draw the whole window now (Blender's own redraw timer), so the next screenshot shows the current state;
        ``area``: the area whose context runs it when the 3D viewport is not there (it shows another editor)."""
        context = self.context() if area is None else {
            "window": self.window, "screen": self.window.screen, "area": area,
            "region": next(r for r in area.regions if r.type == "WINDOW")}
        with bpy.context.temp_override(**context):
            bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=iterations)

    def screenshot(self, name=None, region=None):
        """The viewport's pixels as a (h, w, 3) uint8 array, top row first (``xwd`` of the X screen: what a person
        sees). Saved as ``OUT/NAME.png`` when named."""
        region = region or self.region
        png = self.out / f"{name or '_last'}.png"
        subprocess.run(f"xwd -root -silent | convert xwd:- -crop {region.width}x{region.height}+{region.x}+"
                       f"{self.window.height - region.y - region.height} +repage {png}", shell=True, check=True)
        raw = subprocess.run(["convert", str(png), "-depth", "8", "rgb:-"], check=True, capture_output=True).stdout
        image = np.frombuffer(raw, np.uint8).reshape(region.height, region.width, 3)
        if name is None:
            png.unlink()
        return image

    def event(self, type, value, **kw):
        """Inject one event (window coordinates, y from the bottom)."""
        return self.window.event_simulate(type=type, value=value, **kw)

    def click(self, x, y, button="LEFTMOUSE"):
        self.event("MOUSEMOVE", "NOTHING", x=x, y=y)
        self.key(button, x, y)

    def key(self, key, x, y, **kw):
        """Press and release ``key`` (or a mouse button) at window point (x, y); ``kw``: ``ctrl=True``, ``unicode``."""
        self.event(key, "PRESS", x=x, y=y, **kw)
        kw.pop("unicode", None)
        self.event(key, "RELEASE", x=x, y=y, **kw)


def _after_startup(w, steps):
    """``steps`` once the add-on's start-up work is done (its node-group library, written by a worker Blender), so
    that no scenario's events and timings share the CPU with that Blender's start."""
    from common import after_startup

    yield from after_startup(w)
    return (yield from steps)


def main():
    prefs = bpy.context.preferences
    prefs.view.show_splash = False
    prefs.system.viewport_aa = "OFF"  # one sample: a screenshot is the same every time it is taken
    w = Window()
    steps = None

    def finish(error=None):
        if error:
            w.results["error"] = error
        else:
            w.results["finished"] = True
        (OUT / "results.json").write_text(json.dumps(w.results, indent=1, default=str))
        print(f"window scenario {SCENARIO}: {'finished' if not error else 'FAILED'}", flush=True)
        bpy.ops.wm.quit_blender()

    def step():
        nonlocal steps
        try:
            if steps is None:
                import gpu

                w.results["gpu"] = f"{gpu.platform.backend_type_get()} {gpu.platform.renderer_get()}"
                enable_addon()
                sys.path.insert(0, str(SRC / "tests" / "window" / "scenarios"))
                started = time.perf_counter()
                scenario = __import__(SCENARIO)
                steps = scenario.run(w)
                if getattr(scenario, "AFTER_STARTUP", True):  # the add-on's start-up work done first
                    steps = _after_startup(w, steps)
                w.results["setup_s"] = time.perf_counter() - started
            delay = next(steps)
            return max(float(delay), 0.01)
        except StopIteration:
            finish()
        except Exception:  # noqa: BLE001 -- the scenario's error goes to the results, then Blender quits
            traceback.print_exc()
            finish(traceback.format_exc())
        return None

    bpy.app.timers.register(step, first_interval=1.0)


if os.environ.get("TESSERA_WINDOW_DRIVER_IMPORT") != "1":
    main()

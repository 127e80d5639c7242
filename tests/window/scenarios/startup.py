"""The add-on enabled in a fresh window, as after an install: its node-group library is written by a worker Blender
while the window keeps running, and the "Tessera" asset library appears when it is done. Records whether a writer
was seen running, the seconds until the entry appeared, the longest gap between turns of the event loop meanwhile
(ms) against one redraw, and the entry's path and whether the library there is complete."""

import time

import bpy
from common import region_ms

TIMEOUT_S = 120.0
AFTER_STARTUP = False  # this scenario watches the start-up work itself


def run(w):
    r = w.results
    lib = w.module("addon.node_library")
    r["redraw_ms"] = region_ms(w)
    start = last = time.perf_counter()
    longest, seen = 0.0, False
    while time.perf_counter() - start < TIMEOUT_S:
        yield 0.0
        now = time.perf_counter()
        longest, last = max(longest, now - last), now
        seen = seen or lib._writer.get("job") is not None
        if lib._entries() and not lib._writer:
            break
    r["library_s"] = time.perf_counter() - start
    r["longest_gap_ms"] = 1000.0 * longest
    r["writer_seen"] = seen
    entries = [e.path for e in bpy.context.preferences.filepaths.asset_libraries if e.name == lib.LIBRARY_NAME]
    r["entries"] = entries
    r["complete"] = bool(entries) and lib._complete(lib.Path(entries[0]))

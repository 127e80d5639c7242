"""In a real Blender window (the window tier's packaged Blender under Xvfb, Mesa llvmpipe for OpenGL and lavapipe for
Vulkan; `tools/window_run.sh`): what a redraw of the 3D viewport costs with each preview on, against Blender drawing
that preview's applied mesh of the same triangles in the same window and run (``wm.redraw_timer`` on the viewport
region, 20 redraws); and the longest the main thread is held beyond one viewport redraw during an impostor bake, a
live board's first render and an orbit around the board (the gap between two turns of the event loop). The scenario
is ``tests/window/scenarios/bench_window.py``. Needs root (the tier's chroot and mount namespace); elsewhere it prints
one row saying why and measures nothing.
Run: .venv/bin/python bench/window.py
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BACKENDS = ("opengl", "vulkan")


def main():
    if os.geteuid() != 0 or shutil.which("unshare") is None:
        print(json.dumps({"case": "skipped", "why": "the window bench needs root and unshare (the window tier)"}))
        return 0
    failed = 0
    for backend in BACKENDS:
        out = Path(tempfile.mkdtemp(prefix=f"tessera-window-bench-{backend}-"))
        try:
            done = subprocess.run(["bash", str(ROOT / "tools" / "window_run.sh"), str(out), "bench_window", backend,
                                   "600"], capture_output=True, text=True)
            results = out / "results.json"
            r = json.loads(results.read_text()) if results.exists() else {}
            if not r.get("finished"):
                failed += 1
                sys.stderr.write(f"bench/window.py ({backend}): {r.get('error') or done.stderr[-2000:]}\n")
                continue
            gpu = r.get("gpu") or backend
            for row in r["rows"]:
                print(json.dumps({"case": row.pop("case"), "backend": gpu.split(" (")[0], **row}), flush=True)
        finally:
            shutil.rmtree(out, ignore_errors=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

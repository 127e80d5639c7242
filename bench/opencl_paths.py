"""The OpenCL paths on whichever device the runtime picks, against their numpy references in the same run.

For comparing devices (PoCL on the CPU, a GPU): run it once per device with ``TESSERA_OPENCL_DEVICE``.
- ``tubes``: `kernels.tubes.builder.build_tubes` for 100,000 strands x 32 points, 8 sides, no caps, no UVs (25.6M
  vertices, output in host memory as the operator needs it), OpenCL against numpy; best of 3.
- ``loop_level_<L>``: `kernels.subdivision.loop.loop_subdivide` of a 4,050-triangle height field, levels 4 to 6 (up to
  16.8M triangles), OpenCL against numpy; best of 3.
Each row also gives the largest difference between the two outputs' positions. Prints one JSON object per case.
Run: make bench, or TESSERA_OPENCL_DEVICE=<name> .venv/bin/python bench/opencl_paths.py
"""

import json

import numpy as np
from _setup import best_of, import_path

REPEAT = 3
STRANDS, POINTS, SIDES = 100_000, 32, 8


def row(case, device, seconds, numpy_seconds, diff, **extra):
    return {"bench": "opencl_paths", "case": case, "device": device, **extra, "opencl_seconds": round(seconds, 3),
            "baseline": "numpy reference", "numpy_seconds": round(numpy_seconds, 3),
            "speed_ratio": round(numpy_seconds / seconds, 2), "max_abs_position_difference": diff}


def tubes_case(device):
    from tessera.kernels.tubes.builder import TubeSettings, build_tubes
    from tessera.kernels.tubes.polylines import Polylines

    rng = np.random.default_rng(0)
    walks = np.cumsum(rng.normal(scale=0.01, size=(STRANDS, POINTS, 3)), axis=1)
    pts = (walks + rng.uniform(-1, 1, (STRANDS, 1, 3))).reshape(-1, 3)
    lines = Polylines.build(pts, np.arange(0, STRANDS * POINTS + 1, POINTS), radius=0.005)
    settings = TubeSettings(sides=SIDES, caps="NONE", uvs=False)
    cl, a = best_of(lambda: build_tubes(lines, settings, backend="opencl").positions, REPEAT)
    ref, b = best_of(lambda: build_tubes(lines, settings, backend="numpy").positions, REPEAT)
    return row("tubes", device, cl, ref, float(np.abs(a - b).max()), vertices=len(a))


def loop_cases(device):
    from tessera.kernels.subdivision.loop import loop_subdivide
    from tessera.tools.generators import grid

    pos, tris = grid(45)  # 4,050 triangles, on a bumpy height field so no coordinate is trivially exact
    pos[:, 2] = np.sin(0.3 * pos[:, 0]) * np.cos(0.2 * pos[:, 1])
    for level in (4, 5, 6):
        cl, a = best_of(lambda lv=level: loop_subdivide(pos, tris, lv, backend="opencl"), REPEAT)
        ref, b = best_of(lambda lv=level: loop_subdivide(pos, tris, lv, backend="numpy"), REPEAT)
        yield row(f"loop_level_{level}", device, cl, ref, float(np.abs(a.positions - b.positions).max()),
                  triangles=len(a.triangles))


def main():
    import_path()
    from tessera.kernels.common.opencl_runtime import get_runtime

    runtime = get_runtime()
    if runtime is None:
        print(json.dumps({"bench": "opencl_paths", "case": "skipped", "why": "no OpenCL device"}))
        return
    print(json.dumps(tubes_case(runtime.description)))
    for r in loop_cases(runtime.description):
        print(json.dumps(r))


if __name__ == "__main__":
    main()

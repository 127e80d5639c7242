"""Refinement-pattern core throughput, against writing the output arrays once (a memory-bandwidth floor).

Case: a 100k-triangle grid at uniform levels 4 and 8, and random adaptive levels 1..16; refine + linear
positions, numpy, best of 3. Prints one JSON object per case. Run: make bench, or .venv/bin/python bench/refine.py
"""

import json
import time

import numpy as np
from _setup import import_path

REPEAT = 3


def main():
    import_path()
    from tessera.kernels.common.topology import triangle_edges
    from tessera.kernels.tessellation.interpolate import point_values
    from tessera.kernels.tessellation.refine import refine
    from tessera.tools.generators import grid

    pos, tris = grid(224)  # 100,352 triangles
    edges, _, _ = triangle_edges(tris)
    rng = np.random.default_rng(0)
    cases = {"uniform_4": np.full(len(edges), 4.0), "uniform_8": np.full(len(edges), 8.0),
             "adaptive_1_16": rng.uniform(1, 16, len(edges))}
    for name, levels in cases.items():
        seconds = float("inf")
        for _ in range(REPEAT):  # best of: the first run pays the first touch of fresh memory, which swings 2x here
            t = time.perf_counter()
            ref = refine(tris, len(pos), levels)
            out = point_values(ref, pos, backend="numpy")
            seconds = min(seconds, time.perf_counter() - t)
        floor = out.copy(), ref.triangles.copy()  # touched, so the timed copy has no page faults
        t = time.perf_counter()
        floor[0][...] = out
        floor[1][...] = ref.triangles
        copy = time.perf_counter() - t
        print(json.dumps({"bench": "refine", "case": name, "input_triangles": len(tris),
                          "output_triangles": len(ref.triangles), "seconds": round(seconds, 4),
                          "triangles_per_second": round(len(ref.triangles) / seconds),
                          "baseline": "copy of the output positions and triangles", "baseline_seconds": round(copy, 5),
                          "ratio_to_floor": round(seconds / copy, 1)}))


if __name__ == "__main__":
    main()

"""Terrain level of detail: triangles along a camera path, selection time, HAM throughput, out-of-core memory.

- ``path``: a 12-frame flight over a 4097² synthetic map (texel 1 m, 600 m relief, tiles of 64, ε = 3 px at
  1280x720). Per mode of [Nunes 2011]'s Fig. 5.6 (full grid, uniform 64, distance LOD without T_max, ours, ours with
  frustum culling): mean and max triangles per frame, and the ratio to the full grid (one quad per texel: the
  mesh with no screen-space error at all). Ours bounds each tile's peak error by ε.
- ``select``: level selection per frame (numpy) on the 4097² map and on a 16385² map (65,536 tiles), against a
  frame at 60 Hz (16.7 ms).
- ``ham``: HAM + tile table throughput, numpy against OpenCL, same map, same run (Msamples/s).
- ``out_of_core``: a 16385² raw r16 file (512 MiB; ``--full``: 65537², 8 GiB) analysed memory-mapped, band by
  band: peak Python-side allocation (tracemalloc) against the size of the map as float32.
Prints one JSON object per case. Run: make bench, or .venv/bin/python bench/terrain.py
"""

import atexit
import json
import os
import shutil
import sys
import tempfile
import time
import tracemalloc

import numpy as np
from _setup import import_path

import_path()
from tessera.kernels.common.camera import Camera  # noqa: E402
from tessera.kernels.common.opencl_runtime import get_runtime  # noqa: E402
from tessera.kernels.terrain import heightmap_io as hio  # noqa: E402
from tessera.kernels.terrain import opencl_path as terrain_opencl  # noqa: E402
from tessera.kernels.terrain.analysis import ham, tile_table  # noqa: E402
from tessera.kernels.terrain.lod import TerrainLod, select  # noqa: E402
from tessera.kernels.terrain.mesh import triangle_count  # noqa: E402
from tessera.tools.ridged_terrain import ridged_terrain  # noqa: E402

SIZE = 4097
MODES = {"uniform_64": TerrainLod(mode="UNIFORM", culling=False),
         "distance_only": TerrainLod(mode="DISTANCE", culling=False),
         "ours": TerrainLod(culling=False), "ours_culled": TerrainLod(culling=True)}


def path_cameras(hm, frames=12):
    half = (hm.width - 1) * hm.texel_size / 2
    for k in range(frames):
        a = -0.9 + 1.8 * k / (frames - 1)
        eye = (half * 0.9 * np.sin(a), -half * 1.1 + half * 0.8 * k / frames, 700.0 - 25 * k)
        yield Camera.looking_at(eye, (half * 0.3 * np.sin(2 * a), half * 0.2, 150.0), fov_deg=55, width=1280,
                                height=720, far=10 * half)


def timed(fn, repeat=3):
    best = None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        dt = time.perf_counter() - t
        best = dt if best is None else min(best, dt)
    return out, best


def main():
    heights = ridged_terrain(SIZE, seed=4) * 600.0
    hm = hio.from_array(heights, texel_size=1.0)
    table, t_np = timed(lambda: tile_table(hm, 64, backend="numpy"), 1)
    runtime = get_runtime()
    samples = hm.width * hm.height
    case = {"case": "ham", "map": f"{SIZE}x{SIZE}", "numpy_msamples_per_s": samples / t_np / 1e6}
    _, t_ham = timed(lambda: ham(hm.heights()), 1)
    case["numpy_ham_only_msamples_per_s"] = samples / t_ham / 1e6
    if runtime is not None:
        tile_table(hm, 64, backend="opencl")  # build the program once
        _, t_cl = timed(lambda: tile_table(hm, 64, backend="opencl"))
        _, t_cl_ham = timed(lambda: terrain_opencl.ham(runtime, hm.heights()))
        case.update(opencl_msamples_per_s=samples / t_cl / 1e6, opencl_ham_only_msamples_per_s=samples / t_cl_ham / 1e6,
                    opencl_over_numpy=t_np / t_cl, device=runtime.description)
    print(json.dumps(case))

    full = 2 * (hm.width - 1) * (hm.height - 1)
    counts = {m: [] for m in MODES}
    sel_times = []
    for cam in path_cameras(hm):
        for name, settings in MODES.items():
            sel, dt = timed(lambda s=settings, c=cam: select(hm, table, c, s), 1)
            counts[name].append(triangle_count(sel))
            if name == "ours_culled":
                sel_times.append(dt)
    out = {"case": "path", "map": f"{SIZE}x{SIZE}", "frames": len(sel_times), "full_grid_triangles": full}
    for name, c in counts.items():
        out[name] = {"mean_triangles": float(np.mean(c)), "max_triangles": int(np.max(c)),
                     "fraction_of_full_grid": float(np.mean(c) / full)}
    out["ours_culled_vs_distance_only"] = float(np.mean(counts["ours_culled"]) / np.mean(counts["distance_only"]))
    print(json.dumps(out))

    select_case = {"case": "select", "frame_budget_ms": 1000 / 60,
                   f"{SIZE}_median_ms": 1e3 * float(np.median(sel_times))}
    for size in (16385, 65537) if "--full" in sys.argv else (16385,):
        big, big_table, peak, path = out_of_core(size, heights)
        print(json.dumps({"case": "out_of_core", "map": f"{big.width}x{big.height}",
                          "file_mib": os.path.getsize(path) / 2**20,
                          "float32_map_mib": big.width * big.height * 4 / 2**20, "peak_alloc_mib": peak / 2**20,
                          "tiles": int(big_table.ham_max.size)}), flush=True)
        times = []
        select(big, big_table, next(iter(path_cameras(big, 6))), TerrainLod())  # builds the cached tile geometry
        for cam in path_cameras(big, 6):
            _, dt = timed(lambda c=cam, m=big, t=big_table: select(m, t, c, TerrainLod()), 1)
            times.append(dt)
        select_case.update({f"{big.width}_median_ms": 1e3 * float(np.median(times)),
                            f"{big.width}_tiles": int(big_table.ham_max.size)})
        os.unlink(path)
    print(json.dumps(select_case))


def out_of_core(size, heights):
    """Write a size² r16 file by tiling the small map (mirrored, so it stays continuous), analyse it mapped."""
    folder = tempfile.mkdtemp(prefix="tessera-terrain-")
    atexit.register(shutil.rmtree, folder, ignore_errors=True)
    path = os.path.join(folder, "big.r16")
    small = np.round(heights / 600.0 * 65535).astype("<u2")
    tile = np.block([[small, small[:, ::-1]], [small[::-1], small[::-1, ::-1]]])
    with open(path, "wb") as f:
        for y0 in range(0, size, 1024):
            rows = np.arange(y0, min(size, y0 + 1024)) % tile.shape[0]
            cols = np.arange(size) % tile.shape[1]
            np.ascontiguousarray(tile[rows][:, cols]).tofile(f)
    big = hio.read_heightmap(path, raw_size=(size, size), scale=600.0)
    tracemalloc.start()
    table = tile_table(big, 64, backend="numpy")
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return big, table, peak, path


if __name__ == "__main__":
    main()

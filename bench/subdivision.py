"""Loop subdivision ([Concheiro et al.]) against OpenSubdiv, VTK, trimesh and Blender, in one run.

Cases (Suzanne, 968 triangles, smooth, except where said):
- ``kernel_<backend>_level_<L>`` for L = 1..6 (B3, time against output triangles): `kernels.subdivision.loop.
  loop_subdivide` (positions, welded triangles, edges and corner edges; OpenCL on PoCL, or the numpy reference)
  against OpenSubdiv's CPU Loop refinement of the same mesh (Far::TopologyRefiner uniform refinement +
  PrimvarRefiner in double, the seconds its C++ measures, through tools/osd_oracle); ``speedup`` > 1: Tessera is
  faster.
- ``vtk_level_<L>``: the kernel (OpenCL) against VTK's vtkLoopSubdivisionFilter (the Update call only), L = 3..5.
- ``trimesh_level_<L>``: the kernel (OpenCL) against trimesh.remesh.subdivide_loop at L = 3..5.
- ``recompute_level_<L>`` (B4): [Concheiro et al.]'s recomputation model, every coarse triangle subdivided from its own
  1-ring (`kernels.subdivision.loop_recompute`, numpy, one patch at a time), against the shared-vertex numpy
  reference at the same level (the same bits out), L = 2, 3.
- ``stencils_opencl_level_<L>`` (B4 on a device): one OpenCL work item per coarse triangle evaluating its stencil
  on its packed 1-ring (`kernels.subdivision.loop_stencils`; shared vertices recomputed by every triangle that
  touches them), against the level-by-level OpenCL kernel (shared vertices computed once), L = 2, 3; the stencils
  are built once per mesh topology (their build time is reported beside).
- ``operator_level_5`` (B6): ``tessera.loop_subdivide`` end to end (read, subdivide, write a new object) on the
  flat-shaded Suzanne *Add > Monkey* gives, against adding Subdivision Surface level 5 and applying it, per output
  triangle (Loop 991,232 triangles, Catmull-Clark 1,007,616).
Timings are the best of REPEAT, the cases interleaved round by round. Prints one JSON object per case.
Run: make bench, or .venv/bin/python bench/subdivision.py
"""

import json
import sys
import time
from pathlib import Path

import numpy as np
from _setup import enable_extension, import_path, timed_operator
from tessellation import SUBSURF_LEVEL, subsurf_apply  # the same baseline as bench/tessellation.py

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools" / "osd_oracle"))
REPEAT = 5
LOOP_LEVEL = 5


def suzanne(bpy, smooth):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.mesh.primitive_monkey_add()
    if smooth:
        bpy.ops.object.shade_smooth()
    return bpy.context.active_object


def timed(fn):
    t = time.perf_counter()
    out = fn()
    return time.perf_counter() - t, out


def vtk_filter(v, f, level):
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray

    points = vtk.vtkPoints()
    points.SetData(numpy_to_vtk(np.ascontiguousarray(v, np.float64), deep=True))
    cells = vtk.vtkCellArray()
    conn = np.hstack([np.full((len(f), 1), 3), f]).astype(np.int64).ravel()
    cells.SetCells(len(f), numpy_to_vtkIdTypeArray(conn, deep=True))
    poly = vtk.vtkPolyData()
    poly.SetPoints(points)
    poly.SetPolys(cells)
    filt = vtk.vtkLoopSubdivisionFilter()
    filt.SetNumberOfSubdivisions(level)
    filt.SetInputData(poly)

    def run():
        filt.Modified()
        filt.Update()
        return filt.GetOutput().GetNumberOfPolys()

    return run


def loop_operator(bpy, ob):
    bpy.context.view_layer.objects.active = ob
    return timed_operator(bpy, lambda: bpy.ops.tessera.loop_subdivide(levels=LOOP_LEVEL))


def row(case, seconds, n, base_name, base_seconds, base_n, **extra):
    rate, base_rate = n / seconds, base_n / base_seconds
    return {"bench": "subdivision", "case": case, "output_triangles": int(n), "seconds": round(seconds, 4),
            "triangles_per_second": round(rate), "baseline": base_name, "baseline_triangles": int(base_n),
            "baseline_seconds": round(base_seconds, 4), "baseline_triangles_per_second": round(base_rate),
            "speedup": round(rate / base_rate, 2), **extra}


def main():
    import_path()
    import bpy
    import osd_oracle
    from tessera.addon import bridge
    from tessera.kernels.subdivision.loop import loop_subdivide
    from trimesh.remesh import subdivide_loop

    ob = suzanne(bpy, smooth=True)
    arrays, _ = bridge.read_mesh(ob.data)
    v, f = arrays.positions.astype(np.float64), arrays.triangles
    for level in range(1, 7):
        best = {"opencl": np.inf, "numpy": np.inf, "osd": np.inf, "vtk": np.inf, "trimesh": np.inf}
        vtk_run = vtk_filter(v, f, level) if 3 <= level <= 5 else None
        n = 0
        for _ in range(REPEAT if level < 6 else 3):  # interleaved rounds
            for backend in ("opencl", "numpy"):
                seconds, res = timed(lambda lv=level, b=backend: loop_subdivide(v, f, lv, backend=b))
                best[backend], n = min(best[backend], seconds), len(res.triangles)
                del res
            ref = osd_oracle.loop_refine(v, f, level)
            best["osd"] = min(best["osd"], ref.seconds_topology + ref.seconds_primvar)
            assert len(ref.triangles) == n
            del ref
            if vtk_run is not None:
                seconds, count = timed(vtk_run)
                best["vtk"] = min(best["vtk"], seconds)
                assert count == n
                seconds, (_, tf) = timed(lambda lv=level: subdivide_loop(v, f, iterations=lv))
                best["trimesh"] = min(best["trimesh"], seconds)
        level_rows = [row(f"kernel_{b}_level_{level}", best[b], n, "OpenSubdiv Far Loop (topology + primvar, C++)",
                          best["osd"], n) for b in ("opencl", "numpy")]
        if vtk_run is not None:
            level_rows += [row(f"vtk_level_{level}", best["opencl"], n, "vtkLoopSubdivisionFilter", best["vtk"], n),
                           row(f"trimesh_level_{level}", best["opencl"], n, "trimesh.remesh.subdivide_loop",
                               best["trimesh"], n)]
        for r in level_rows:
            print(json.dumps(r), flush=True)

    from tessera.kernels.subdivision.loop_recompute import Recomputation

    for level in (2, 3):
        best_rec, best_ref = np.inf, np.inf
        for _ in range(3):
            seconds, out = timed(lambda lv=level: Recomputation(v, f, lv).run(check=False))
            best_rec = min(best_rec, seconds)
            seconds, ref = timed(lambda lv=level: loop_subdivide(v, f, lv, backend="numpy", dtype=np.float64))
            best_ref = min(best_ref, seconds)
            assert np.array_equal(out, ref.positions)
        n = len(f) * 4**level
        print(json.dumps(row(f"recompute_level_{level}", best_rec, n, "shared-vertex numpy reference", best_ref, n,
                             patches=len(f))), flush=True)

    from tessera.kernels.common.opencl_runtime import get_runtime
    from tessera.kernels.subdivision import loop_stencils

    runtime = get_runtime()
    for level in (2, 3):
        build_seconds, table = timed(lambda lv=level: loop_stencils.build(v, f, lv))
        best_st, best_lv = np.inf, np.inf
        for _ in range(REPEAT):
            seconds, out = timed(lambda t=table: loop_stencils.apply_opencl(runtime, t, v))
            best_st = min(best_st, seconds)
            seconds, _ = timed(lambda lv=level: loop_subdivide(v, f, lv, backend="opencl"))
            best_lv = min(best_lv, seconds)
        n = len(f) * 4**level
        print(json.dumps(row(f"stencils_opencl_level_{level}", best_st, n, "level-by-level OpenCL kernel", best_lv,
                             n, stencils=len(table.weights), stencil_build_seconds=round(build_seconds, 3))),
              flush=True)

    ob = suzanne(bpy, smooth=False)
    enable_extension()  # after the factory settings are read
    best_op, best_sub, n_op, n_sub = np.inf, np.inf, 0, 0
    for _ in range(REPEAT):
        seconds, n_op = loop_operator(bpy, ob)
        best_op = min(best_op, seconds)
        seconds, n_sub = subsurf_apply(bpy, ob, repeat=1)  # one per round: the rounds interleave
        best_sub = min(best_sub, seconds)
    print(json.dumps(row(f"operator_level_{LOOP_LEVEL}", best_op, n_op,
                         f"Subdivision Surface level {SUBSURF_LEVEL} add + apply", best_sub, n_sub,
                         input="flat-shaded Suzanne (Add > Monkey)")), flush=True)


if __name__ == "__main__":
    main()

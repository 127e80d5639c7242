"""PN / Phong tessellation against Blender's Subdivision Surface modifier (OpenSubdiv), in one run.

Cases on a smooth-shaded Suzanne (968 triangles):
- ``kernel``: `kernels.tessellation.tessellate.tessellate` (refinement, positions, unit normals, welded triangles) at a
  uniform level whose output is about one million triangles, for PN and Phong; baseline: the modifier
  evaluated to about the same triangle count (level 5), rates compared in triangles per second.
- ``floor``: writing the kernel's output arrays once (positions, normals, triangles, UVs) into preallocated
  arrays; the kernel's time over it is the distance from the memory-bandwidth floor.
- ``operator_<method>_<shading>``: ``tessera.tessellate`` end to end (read, tessellate, write a new object) against
  adding the modifier and applying it to the mesh, triangles per second, on the smooth-shaded Suzanne and on the
  flat-shaded one (what *Add > Monkey* gives: every edge sharp, split corner normals written as custom normals).
- ``operator_pn_adaptive``: adaptive PN (fractional-even, projected edge length of 3 px for a 1920x1080 camera)
  end to end against the operator at the uniform level giving about as many triangles, per output triangle;
  ``operator_pn_adaptive_equal``: the same levels with equal spacing (rounded up to whole segments, so faces fall
  into pattern classes); ``operator_pn_adaptive_dense``: fractional-even on Suzanne subdivided twice (15,744
  triangles, 4 px), where every face has a level of its own and few output triangles.
- ``first_call``: in a fresh process, importing bpy, enabling Tessera and the first operator call, against a warm
  call of the same operator.
Prints one JSON object per case. Run: make bench, or .venv/bin/python bench/tessellation.py
"""

import json
import time

import numpy as np
from _setup import best_of, enable_extension, import_path, timed_operator

LEVEL = 26  # 968 * floor(3 * 26^2 / 2) = 981,552 triangles
SUBSURF_LEVEL = 5  # 1,007,616 triangles
REPEAT = 5
KERNEL_REPEAT = 25  # the kernel runs ~10 ms: more tries for the best of a noisy shared machine


def suzanne(bpy):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.mesh.primitive_monkey_add()
    bpy.ops.object.shade_smooth()
    return bpy.context.active_object


def subsurf_evaluate(bpy, ob):
    """Seconds to evaluate the modifier at SUBSURF_LEVEL (best of REPEAT) and its triangle count."""
    mod = ob.modifiers.new("Subdivision", "SUBSURF")
    depsgraph = bpy.context.evaluated_depsgraph_get()

    def run():
        mod.levels = 0
        depsgraph.update()
        t = time.perf_counter()
        mod.levels = SUBSURF_LEVEL
        depsgraph.update()
        n = len(ob.evaluated_get(depsgraph).data.polygons) * 2  # quads
        return time.perf_counter() - t, n

    runs = [run() for _ in range(REPEAT)]
    ob.modifiers.remove(mod)
    return min(r[0] for r in runs), runs[0][1]


def subsurf_apply(bpy, ob, repeat=REPEAT):
    """Seconds to add the modifier and apply it to a copy of the mesh (best of ``repeat``), and the triangle
    count."""
    best, n = float("inf"), 0
    for _ in range(repeat):
        copy = ob.copy()
        copy.data = ob.data.copy()
        bpy.context.scene.collection.objects.link(copy)
        bpy.context.view_layer.objects.active = copy
        t = time.perf_counter()
        mod = copy.modifiers.new("Subdivision", "SUBSURF")
        mod.levels = SUBSURF_LEVEL
        bpy.ops.object.modifier_apply(modifier=mod.name)
        best = min(best, time.perf_counter() - t)
        n = len(copy.data.polygons) * 2
        me = copy.data
        bpy.data.objects.remove(copy)
        bpy.data.meshes.remove(me)
    return best, n


def operator_run(bpy, ob, method, repeat=REPEAT, **options):
    best, n = float("inf"), 0
    options = {"level": LEVEL, **options}
    for _ in range(repeat):
        bpy.context.view_layer.objects.active = ob
        seconds, n = timed_operator(bpy, lambda: bpy.ops.tessera.tessellate(method=method, **options))
        best = min(best, seconds)
    return best, n


def main():
    import_path()
    import bpy
    from tessera.addon import bridge
    from tessera.kernels.tessellation.tessellate import tessellate, uniform_levels

    ob = suzanne(bpy)
    arrays, _ = bridge.read_mesh(ob.data)
    levels = uniform_levels(arrays, LEVEL)
    sub_eval, sub_tris = subsurf_evaluate(bpy, ob)
    sub_rate = sub_tris / sub_eval
    gpu = "none (CPU evaluation in background mode)"
    rows = []
    for method in ("PHONG", "PN"):
        seconds, result = best_of(lambda m=method: tessellate(arrays, levels, method=m, backend="numpy"),
                                  KERNEL_REPEAT)
        out = result.mesh
        rate = len(out.triangles) / seconds
        rows.append({"bench": "tessellation", "case": f"kernel_{method.lower()}",
                     "output_triangles": len(out.triangles), "output_vertices": len(out.positions),
                     "seconds": round(seconds, 4),
                     "triangles_per_second": round(rate), "baseline": f"SUBSURF level {SUBSURF_LEVEL} evaluation",
                     "baseline_triangles": sub_tris, "baseline_seconds": round(sub_eval, 4),
                     "baseline_triangles_per_second": round(sub_rate), "speedup": round(rate / sub_rate, 2),
                     "subdivision_gpu": gpu})
        outputs = [out.positions, out.point_normals, out.triangles, *out.corner_attributes.values()]
        floor_arrays = [np.empty_like(a) for a in outputs]

        def write_once(outputs=outputs, floor_arrays=floor_arrays):
            for dst, src in zip(floor_arrays, outputs, strict=True):
                np.copyto(dst, src)

        floor, _ = best_of(write_once, KERNEL_REPEAT)
        nbytes = sum(a.nbytes for a in floor_arrays)
        rows.append({"bench": "tessellation", "case": f"floor_{method.lower()}", "bytes": nbytes,
                     "seconds": round(seconds, 4), "baseline": "copy of the output arrays once",
                     "baseline_seconds": round(floor, 5), "ratio_to_floor": round(seconds / floor, 1),
                     "floor_gb_per_second": round(nbytes / floor / 1e9, 2)})
    phong, pn = rows[0], rows[2]
    rows.append({"bench": "tessellation", "case": "phong_vs_pn", "phong_seconds": phong["seconds"],
                 "pn_seconds": pn["seconds"], "phong_speedup": round(pn["seconds"] / phong["seconds"], 2)})

    enable_extension()  # the operator, registered as for an installed extension
    for shading in ("smooth", "flat"):  # flat: what Add > Monkey gives (every edge sharp, split corner normals)
        bpy.context.view_layer.objects.active = ob
        ob.select_set(True)
        getattr(bpy.ops.object, f"shade_{shading}")()
        apply_seconds, best = float("inf"), {"PHONG": (float("inf"), 0), "PN": (float("inf"), 0)}
        for _ in range(REPEAT):  # the modifier and both operators one after the other: the same machine for all
            one, apply_tris = subsurf_apply(bpy, ob, repeat=1)
            apply_seconds = min(apply_seconds, one)
            for method in best:
                seconds, n = operator_run(bpy, ob, method, repeat=1)
                best[method] = (min(best[method][0], seconds), n)
        for method, (seconds, n) in best.items():
            rate, base = n / seconds, apply_tris / apply_seconds
            rows.append({"bench": "tessellation", "case": f"operator_{method.lower()}_{shading}",
                         "output_triangles": n, "seconds": round(seconds, 4), "triangles_per_second": round(rate),
                         "baseline": f"SUBSURF level {SUBSURF_LEVEL} add + apply ({shading}-shaded)",
                         "baseline_triangles": apply_tris, "baseline_seconds": round(apply_seconds, 4),
                         "speedup": round(rate / base, 2), "speedup_vs_evaluation_only": round(rate / sub_rate, 2)})
    rows.append(adaptive_case(bpy, ob))
    rows.append(adaptive_case(bpy, ob, "operator_pn_adaptive_equal", spacing="EQUAL"))  # levels rounded up: classes
    dense = ob.copy()  # many small faces that all differ: Suzanne subdivided twice (15,744 triangles)
    dense.data = ob.data.copy()
    bpy.context.scene.collection.objects.link(dense)
    bpy.context.view_layer.objects.active = dense
    dense.modifiers.new("Subdivision", "SUBSURF").levels = 2
    bpy.ops.object.modifier_apply(modifier="Subdivision")
    rows.append(adaptive_case(bpy, dense, "operator_pn_adaptive_dense", edge_pixels=4.0))
    rows.append(first_call_case())
    for row in rows:
        print(json.dumps(row))


def adaptive_case(bpy, ob, case="operator_pn_adaptive", edge_pixels=3.0, spacing="FRACTIONAL_EVEN"):
    """Adaptive PN (fractional-even spacing, projected edge length for a camera) end to end, against the operator at
    the uniform level that gives about as many triangles, in triangles per second; the two run alternately (best
    of REPEAT each) after one untimed adaptive run that sizes the uniform level."""
    import mathutils

    ob.data.shade_smooth()  # the loops above left it flat-shaded
    if bpy.context.scene.camera is None:
        cam = bpy.data.objects.new("bench_camera", bpy.data.cameras.new("bench_camera"))
        bpy.context.scene.collection.objects.link(cam)
        cam.location = (0.0, -2.6, 0.4)
        cam.rotation_euler = (mathutils.Vector((0, 0, 0)) - cam.location).to_track_quat("-Z", "Y").to_euler()
        bpy.context.scene.camera = cam
    render = bpy.context.scene.render
    render.resolution_x, render.resolution_y, render.resolution_percentage = 1920, 1080, 100
    adaptive = {"level_mode": "ADAPTIVE", "spacing": spacing, "metrics": {"PROJECTED"},
                "edge_pixels": edge_pixels, "max_level": 64.0}
    _, n = operator_run(bpy, ob, "PN", repeat=1, **adaptive)
    level = np.sqrt(n / len(ob.data.loop_triangles) / 1.5)  # floor(3 l^2 / 2) triangles a face
    seconds = uniform_seconds = float("inf")
    for _ in range(REPEAT):  # one after the other, so both see the same machine
        seconds = min(seconds, operator_run(bpy, ob, "PN", repeat=1, **adaptive)[0])
        one, uniform_n = operator_run(bpy, ob, "PN", repeat=1, level=float(np.ceil(level)))
        uniform_seconds = min(uniform_seconds, one)
    rate, base = n / seconds, uniform_n / uniform_seconds
    return {"bench": "tessellation", "case": case, "input_triangles": len(ob.data.loop_triangles),
            "output_triangles": n, "edge_pixels": edge_pixels, "spacing": spacing,
            "seconds": round(seconds, 4), "triangles_per_second": round(rate),
            "baseline": f"the operator at uniform level {int(np.ceil(level))} (PN, equal spacing)",
            "baseline_triangles": uniform_n, "baseline_seconds": round(uniform_seconds, 4),
            "per_triangle_ratio": round(base / rate, 2), "target_per_triangle_ratio": 1.3}


FIRST_CALL = """
import sys, time
t0 = time.perf_counter()
sys.path.insert(0, {bench!r})
from _setup import enable_extension, import_path
import_path()
import bpy
t1 = time.perf_counter()
bpy.ops.wm.read_factory_settings(use_empty=True)
enable_extension()
t2 = time.perf_counter()
bpy.ops.mesh.primitive_monkey_add()
times = []
for _ in range(3):
    t = time.perf_counter()
    bpy.ops.tessera.tessellate(method="PN", level=8)
    times.append(time.perf_counter() - t)
    bpy.context.view_layer.objects.active = bpy.data.objects["Suzanne"]
print(t1 - t0, t2 - t1, times[0], min(times[1:]))
"""


def first_call_case():
    """A fresh process: importing bpy, enabling Tessera, the first ``tessera.tessellate`` (modules imported,
    worker threads started), against a warm call of the same operator."""
    import subprocess
    import sys
    from pathlib import Path

    script = FIRST_CALL.format(bench=str(Path(__file__).resolve().parent))
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    imp, enable, first, warm = (float(x) for x in out.stdout.split()[-4:])
    return {"bench": "tessellation", "case": "first_call", "import_bpy_seconds": round(imp, 3),
            "enable_seconds": round(enable, 3), "first_operator_seconds": round(first, 4),
            "baseline": "a warm call of the same operator (PN level 8 on Suzanne)", "baseline_seconds": round(warm, 4),
            "first_over_warm": round(first / warm, 1)}


if __name__ == "__main__":
    main()

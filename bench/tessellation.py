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
Prints one JSON object per case. Run: make bench, or .venv/bin/python bench/tessellation.py
"""

import json
import time

import numpy as np
from _setup import best_of, enable_extension, import_path

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


def subsurf_apply(bpy, ob):
    """Seconds to add the modifier and apply it to a copy of the mesh, and the triangle count."""
    best, n = float("inf"), 0
    for _ in range(REPEAT):
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


def operator_run(bpy, ob, method):
    best, n = float("inf"), 0
    for _ in range(REPEAT):
        bpy.context.view_layer.objects.active = ob
        t = time.perf_counter()
        bpy.ops.tessera.tessellate(method=method, level=LEVEL)
        best = min(best, time.perf_counter() - t)
        new = bpy.context.active_object
        n = len(new.data.polygons)
        me = new.data
        bpy.data.objects.remove(new)
        bpy.data.meshes.remove(me)
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
        apply_seconds, apply_tris = subsurf_apply(bpy, ob)
        for method in ("PHONG", "PN"):
            seconds, n = operator_run(bpy, ob, method)
            rate, base = n / seconds, apply_tris / apply_seconds
            rows.append({"bench": "tessellation", "case": f"operator_{method.lower()}_{shading}",
                         "output_triangles": n, "seconds": round(seconds, 4), "triangles_per_second": round(rate),
                         "baseline": f"SUBSURF level {SUBSURF_LEVEL} add + apply ({shading}-shaded)",
                         "baseline_triangles": apply_tris, "baseline_seconds": round(apply_seconds, 4),
                         "speedup": round(rate / base, 2), "speedup_vs_evaluation_only": round(rate / sub_rate, 2)})
    for row in rows:
        print(json.dumps(row))


if __name__ == "__main__":
    main()

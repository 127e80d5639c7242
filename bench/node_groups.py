"""Tessera's geometry-nodes groups against the nearest built-in and the operator, in one run.

- ``<phong|pn>_group``: the "Tessera Phong" / "Tessera PN Triangles" group evaluated as a modifier on a smooth
  Suzanne (968 triangles, Level 4 and 5) against Subdivision Surface evaluated at level 5 on the same object,
  output triangles per second (a quad counts as two triangles); and against ``tessera.tessellate`` (the same
  method, end to end, a new object) at about the same output.
Timings: best of REPEAT, cases interleaved. Prints one JSON object per case. Run: make bench, or
.venv/bin/python bench/node_groups.py
"""

import json
import time

from _setup import enable_extension

REPEAT = 5


def evaluate(bpy, ob, mod, set_level):
    """Seconds to evaluate ``ob`` after ``set_level(mod)`` changes its modifier, and output triangles."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    mod.show_viewport = False
    depsgraph.update()
    set_level(mod)
    t = time.perf_counter()
    mod.show_viewport = True
    depsgraph.update()
    me = ob.evaluated_get(depsgraph).data
    n = sum(len(p.vertices) - 2 for p in me.polygons) if len(me.polygons) < 1000 else 2 * len(me.polygons)
    return time.perf_counter() - t, n


def main():
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    name = enable_extension()
    import importlib

    groups = importlib.import_module(name + ".addon.node_groups")
    bpy.ops.mesh.primitive_monkey_add()
    ob = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    for method, module in (("PHONG", "phong_nodes"), ("PN", "pn_nodes")):
        spec = importlib.import_module(f"{name}.addon.tessellation.{module}").SPEC
        for level in (4, 5):
            run(bpy, ob, groups, spec, method, level)


def run(bpy, ob, groups, spec, method, level):
    """One group at one level against its baselines: prints two JSON rows."""
    best = {"group": float("inf"), "subsurf": float("inf"), "operator": float("inf")}
    counts = {}
    for _ in range(REPEAT):
        mod = ob.modifiers.new(spec.name, "NODES")
        mod.node_group = groups.ensure_group(spec)
        seconds, counts["group"] = evaluate(bpy, ob, mod, lambda m, lv=level: groups.set_inputs(m, {"Level": lv}))
        best["group"] = min(best["group"], seconds)
        ob.modifiers.remove(mod)
        mod = ob.modifiers.new("Subsurf", "SUBSURF")
        seconds, counts["subsurf"] = evaluate(bpy, ob, mod, lambda m: setattr(m, "levels", 5))
        best["subsurf"] = min(best["subsurf"], seconds)
        ob.modifiers.remove(mod)
        tess_level = 14 if level == 4 else 28  # 968 * floor(3 L^2 / 2) triangles: about the group's output
        bpy.context.view_layer.objects.active = ob
        t = time.perf_counter()
        bpy.ops.tessera.tessellate(method=method, level=tess_level)
        best["operator"] = min(best["operator"], time.perf_counter() - t)
        out = bpy.context.active_object
        counts["operator"] = len(out.data.polygons)
        me = out.data
        bpy.data.objects.remove(out)
        bpy.data.meshes.remove(me)
    rate = {k: counts[k] / best[k] for k in best}
    for base, label in (("subsurf", "Subdivision Surface level 5 evaluation"),
                        ("operator", f"tessera.tessellate {method} end to end")):
        print(json.dumps({"bench": "node_groups", "case": f"{method.lower()}_group_level_{level}_vs_{base}",
                          "output_triangles": counts["group"], "seconds": round(best["group"], 4),
                          "triangles_per_second": round(rate["group"]), "baseline": label,
                          "baseline_triangles": counts[base], "baseline_seconds": round(best[base], 4),
                          "baseline_triangles_per_second": round(rate[base]),
                          "speedup": round(rate["group"] / rate[base], 2)}), flush=True)


if __name__ == "__main__":
    main()

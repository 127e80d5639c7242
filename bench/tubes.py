"""Tubes against geometry nodes Curve to Mesh (circle profile) at the same output size, in one run.

Scene: 100,000 strands x 32 points (random walks), 8 sides, no caps -> 25.6 M vertices, 24.8 M quads.
- ``kernel_opencl`` / ``kernel_numpy``: `kernels.tubes.builder.build_tubes` (frames, rings, normals, quads, edges;
  OpenCL on PoCL, or the numpy reference) against evaluating a
  Curve to Mesh modifier on a poly hair-curves object with the same points (Blender builds the mesh with
  its own minimum-twist normals, multithreaded). Ratio > 1: Tessera is faster.
- ``operator``: ``tessera.tubes`` end to end (read the hair, build straight into the new mesh's memory, make the
  object) against the same modifier evaluation plus copying its mesh into a new object (what applying the modifier
  costs), one run of each in turn; best and median of each (removing the results is not timed).
- ``operator_huge_pages``: the operator with huge pages asked for and not (``TESSERA_HUGE_PAGES`` on / off,
  `kernels.common.huge_pages`), interleaved with the same baseline, and what the automatic choice is on this machine
  (off on a virtual machine that hands free memory back to its host, where fresh huge pages cost host faults).
- ``mesh_write``: `bridge.write_polygons` of a kernel output already built (the copy into Blender that the
  operator no longer makes: it hands the kernel the new mesh's arrays), against the same baseline.
- ``operator_first_run``: the first run of each in a fresh process (no freed memory of an earlier run to reuse):
  seconds and peak memory growth (the operator builds straight into the mesh, so it holds the output once); and the
  operator's first run after the add-on's OpenCL warm-up (`addon.opencl_warmup`, which the UI starts a second after
  the add-on is enabled) has made the runtime and built the programs.
- ``preview_bytes``: what the GPU preview uploads (section texture: 48 B per section; patch tables: 16 B per
  patch of up to 63 segments) against uploading the tube mesh for drawing (position + normal per vertex,
  two triangles of 32-bit indices per quad): [Nunes 2011]'s Table 4.2 argument.
- ``memory``: peak resident memory of a fresh process building 1 M strands x 32 points with 3 sides,
  against the size of the output arrays.
Prints one JSON object per case. Run: make bench, or .venv/bin/python bench/tubes.py
"""

import importlib
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from _setup import best_of, enable_extension, import_path, timed_operator

STRANDS, POINTS, SIDES, RADIUS = 100_000, 32, 8, 0.005
REPEAT = 3


def strands(count, points, seed=0):
    rng = np.random.default_rng(seed)
    roots = rng.uniform(-1, 1, (count, 1, 3))
    steps = rng.normal(scale=0.02, size=(count, points, 3))
    steps[:, :, 2] += 0.05
    return (roots + np.cumsum(steps, axis=1)).reshape(-1, 3)


def hair_object(bpy, pts):
    hair = bpy.data.hair_curves.new("bench_strands")
    hair.add_curves([POINTS] * STRANDS)
    hair.set_types(type="POLY")
    hair.attributes["position"].data.foreach_set("vector", pts.astype(np.float32).ravel())
    ob = bpy.data.objects.new("bench_strands", hair)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def curve_to_mesh_group(bpy):
    ng = bpy.data.node_groups.new("bench_curve_to_mesh", "GeometryNodeTree")
    ng.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    ng.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    gin, gout = ng.nodes.new("NodeGroupInput"), ng.nodes.new("NodeGroupOutput")
    to_mesh = ng.nodes.new("GeometryNodeCurveToMesh")
    circle = ng.nodes.new("GeometryNodeCurvePrimitiveCircle")
    circle.inputs["Resolution"].default_value = SIDES
    circle.inputs["Radius"].default_value = RADIUS
    ng.links.new(gin.outputs[0], to_mesh.inputs["Curve"])
    ng.links.new(circle.outputs["Curve"], to_mesh.inputs["Profile Curve"])
    ng.links.new(to_mesh.outputs["Mesh"], gout.inputs[0])
    return ng


def geometry_nodes(bpy, ob, copy_mesh, repeat=REPEAT):
    """Seconds of each of ``repeat`` evaluations of Curve to Mesh (each optionally copying the result into a new
    object), and the vertex count; the clean-up after each is not timed."""
    mod = ob.modifiers.new("CurveToMesh", "NODES")
    mod.node_group = curve_to_mesh_group(bpy)
    depsgraph = bpy.context.evaluated_depsgraph_get()

    def run():
        mod.show_viewport = False
        depsgraph.update()
        t = time.perf_counter()
        mod.show_viewport = True
        depsgraph.update()
        evaluated = ob.evaluated_get(depsgraph)
        geometry = bpy.types.GeometrySet.from_evaluated_object(evaluated)
        n = len(geometry.mesh.vertices)
        if copy_mesh:
            me = geometry.mesh.copy()  # the evaluated mesh into bpy.data, as applying the modifier would
            copy = bpy.data.objects.new("bench_copy", me)
            bpy.context.scene.collection.objects.link(copy)
            n = len(me.vertices)
        seconds = time.perf_counter() - t
        if copy_mesh:
            bpy.data.objects.remove(copy)
            bpy.data.meshes.remove(me)
        return seconds, n

    runs = [run() for _ in range(repeat)]
    ob.modifiers.remove(mod)
    return [r[0] for r in runs], runs[0][1]


def kernel_case(pts, backend):
    from tessera.kernels.tubes.builder import TubeSettings, build_tubes
    from tessera.kernels.tubes.polylines import Polylines

    lines = Polylines.build(pts, np.arange(0, STRANDS * POINTS + 1, POINTS), radius=RADIUS)
    settings = TubeSettings(sides=SIDES, caps="NONE", uvs=False)
    seconds, mesh = best_of(lambda: len(build_tubes(lines, settings, backend=backend).positions), REPEAT)
    return seconds, mesh


def operator_run(bpy, ob):
    """Seconds of one ``tessera.tubes`` run on ``ob`` (its result removed afterwards, untimed) and the vertex count."""
    for other in bpy.context.selected_objects:
        other.select_set(False)
    ob.select_set(True)
    bpy.context.view_layer.objects.active = ob
    bpy.context.view_layer.update()  # as in the UI, where the scene is evaluated before the click (bpy.ops would
    # otherwise evaluate the hair object again inside the timed call)
    return timed_operator(bpy, lambda: bpy.ops.tessera.tubes(radius_source="CONSTANT", radius=RADIUS, sides=SIDES,
                                                             caps="NONE", uvs=False), count="vertices")


def operator_case(bpy, ob, rounds=2 * REPEAT):
    """The operator against Curve to Mesh + a new object, one run of each in turn (so both see the same state of
    the machine's memory): best and median seconds of each."""
    ours, theirs, n = [], [], 0
    for _ in range(rounds):
        theirs += geometry_nodes(bpy, ob, copy_mesh=True, repeat=1)[0]
        seconds, n = operator_run(bpy, ob)
        ours.append(seconds)
    return {"case": "operator", "vertices": n, "baseline": "Curve to Mesh evaluation + copy of its mesh into a new "
            "object, runs interleaved", "seconds": round(min(ours), 3), "median_seconds": round(np.median(ours), 3),
            "baseline_seconds": round(min(theirs), 3), "baseline_median_seconds": round(np.median(theirs), 3),
            "speed_ratio": round(min(theirs) / min(ours), 2),
            "median_speed_ratio": round(np.median(theirs) / np.median(ours), 2)}


def huge_pages_case(bpy, ob, rounds=2 * REPEAT):
    """The operator with huge pages forced on and off against Curve to Mesh + a new object, interleaved: best and
    median seconds of each, and the automatic choice here. With huge pages on, two runs follow each other: the first
    ("on_fresh") gets its 2 MiB pages wherever the system has them, the second ("on_recycled") the pages the first
    just freed, which is where every huge page comes from on a machine that keeps its free memory (on a virtual
    machine that hands free memory back to its host, fresh ones cost the host a fault per 4 KiB)."""
    huge = importlib.import_module(f"{enable_extension()}.kernels.common.huge_pages")
    times = {"on_fresh": [], "on_recycled": [], "off": [], "baseline": []}
    before = os.environ.get("TESSERA_HUGE_PAGES", "auto")
    try:
        for _ in range(rounds):
            times["baseline"] += geometry_nodes(bpy, ob, copy_mesh=True, repeat=1)[0]
            for mode, env in (("on_fresh", "on"), ("on_recycled", "on"), ("off", "off")):
                os.environ["TESSERA_HUGE_PAGES"] = env
                times[mode].append(operator_run(bpy, ob)[0])
    finally:
        os.environ["TESSERA_HUGE_PAGES"] = before
    out = {"case": "operator_huge_pages", "automatic_choice": "on" if huge.auto_choice() else "off",
           "reports_free_pages": huge.reports_free_pages("/sys"),
           "baseline": "Curve to Mesh evaluation + copy into a new object, runs interleaved"}
    base = times.pop("baseline")
    for mode, seconds in times.items():
        out[f"{mode}_seconds"] = round(min(seconds), 3)
        out[f"{mode}_median_seconds"] = round(float(np.median(seconds)), 3)
        out[f"{mode}_speed_ratio"] = round(min(base) / min(seconds), 2)
        out[f"{mode}_median_speed_ratio"] = round(float(np.median(base) / np.median(seconds)), 2)
    out["baseline_seconds"], out["baseline_median_seconds"] = round(min(base), 3), round(float(np.median(base)), 3)
    return out


def write_case(bpy, pts):
    """`bridge.write_polygons` of a built mesh: the copy into Blender that the operator no longer makes."""
    from tessera.addon.bridge import write_polygons
    from tessera.kernels.tubes.builder import TubeSettings, build_tubes
    from tessera.kernels.tubes.polylines import Polylines

    lines = Polylines.build(pts, np.arange(0, STRANDS * POINTS + 1, POINTS), radius=RADIUS)
    poly = build_tubes(lines, TubeSettings(sides=SIDES, caps="NONE", uvs=False))

    def run():
        mesh = write_polygons("bench_write", poly)
        n = len(mesh.vertices)
        bpy.data.meshes.remove(mesh)
        return n

    return best_of(run, REPEAT)


def preview_case(pts):
    from tessera.gpu_shaders.tubes.draw import patch_table, section_order
    from tessera.kernels.tubes.polylines import Polylines

    lines = Polylines.build(pts, np.arange(0, STRANDS * POINTS + 1, POINTS), radius=RADIUS)
    sections = len(section_order(lines)) * 48
    patches = len(patch_table(lines)[0]) * 16
    quads = STRANDS * (POINTS - 1) * SIDES
    mesh = STRANDS * POINTS * SIDES * 24 + quads * 2 * 3 * 4
    return {"case": "preview_bytes", "preview_upload_mib": round((sections + patches) / 2**20, 1),
            "mesh_upload_mib": round(mesh / 2**20, 1), "ratio": round(mesh / (sections + patches), 1)}


MEMORY_CHILD = """
import resource, sys
sys.path.insert(0, sys.argv[1])
import numpy as np
from tessera.kernels.tubes.polylines import Polylines
from tessera.kernels.tubes.builder import TubeSettings, build_tubes
count, points = 1_000_000, 32
rng = np.random.default_rng(1)
pts = rng.normal(scale=0.02, size=(count, points, 3)).cumsum(axis=1).reshape(-1, 3)
lines = Polylines.build(pts, np.arange(0, count * points + 1, points), radius=0.005)
del pts
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
mesh = build_tubes(lines, TubeSettings(sides=3, caps="NONE", uvs=False))
out = sum(a.nbytes for a in (mesh.positions, mesh.point_normals, mesh.corner_verts, mesh.corner_edges, mesh.edges,
                             mesh.face_offsets, mesh.face_material) if a is not None)
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(before * 1024, peak * 1024, out, len(mesh.positions))
"""


def memory_case():
    folder = import_path()
    proc = subprocess.run([sys.executable, "-c", MEMORY_CHILD, str(folder)], capture_output=True, text=True,
                          check=True)
    before, peak, out, verts = (int(x) for x in proc.stdout.split())
    return {"case": "memory", "strands": 1_000_000, "points": 32, "sides": 3, "vertices": verts,
            "peak_rss_mib": round(peak / 2**20), "input_rss_mib": round(before / 2**20),
            "output_mib": round(out / 2**20), "peak_over_input_plus_output": round(peak / (before + out), 2)}


FRESH_CHILD = """
import importlib, json, resource, sys
sys.path.insert(0, sys.argv[1])
import bpy
import tubes as tb
from _setup import enable_extension
bpy.ops.wm.read_factory_settings(use_empty=True)
name = enable_extension()
ob = tb.hair_object(bpy, tb.strands(tb.STRANDS, tb.POINTS))
if sys.argv[2] == "warmed":  # what the UI does a second after the add-on is enabled, long before a first click
    importlib.import_module(name + ".addon.opencl_warmup").start().join()
with open("/proc/self/statm") as statm:  # resident now (the setup's own peak may lie above it), in KiB
    before = int(statm.read().split()[1]) * resource.getpagesize() // 1024
if sys.argv[2] in ("operator", "warmed"):
    seconds, n = tb.operator_run(bpy, ob)
else:
    seconds, n = tb.geometry_nodes(bpy, ob, copy_mesh=True, repeat=1)[0][0], 0
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(json.dumps({"seconds": seconds, "growth": (peak - before) * 1024}))
"""


def fresh_case():
    """The first run in a fresh Blender of the operator and of Curve to Mesh + a new object (the run a user waits
    for: no memory of an earlier run to reuse), each in its own process: seconds and peak memory growth."""
    folder = str(Path(__file__).resolve().parent)
    out = {}
    for mode in ("baseline", "operator", "warmed"):
        proc = subprocess.run([sys.executable, "-c", FRESH_CHILD, folder, mode], capture_output=True, text=True,
                              check=True)
        out[mode] = json.loads(proc.stdout.strip().splitlines()[-1])
    ours, theirs, warmed = out["operator"], out["baseline"], out["warmed"]
    return {"case": "operator_first_run", "baseline": "Curve to Mesh evaluation + copy into a new object, first run "
            "in a fresh process", "seconds": round(ours["seconds"], 3), "baseline_seconds": round(theirs["seconds"], 3),
            "speed_ratio": round(theirs["seconds"] / ours["seconds"], 2),
            "after_warm_up_seconds": round(warmed["seconds"], 3),
            "after_warm_up_speed_ratio": round(theirs["seconds"] / warmed["seconds"], 2),
            "peak_growth_mib": round(ours["growth"] / 2**20),
            "baseline_peak_growth_mib": round(theirs["growth"] / 2**20)}


def main():
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    enable_extension()
    pts = strands(STRANDS, POINTS)
    ob = hair_object(bpy, pts)
    gn_evals, gn_verts = geometry_nodes(bpy, ob, copy_mesh=False)
    gn_eval = min(gn_evals)
    for backend in ("opencl", "numpy"):
        ours, verts = kernel_case(pts, backend)
        print(json.dumps({"case": f"kernel_{backend}", "strands": STRANDS, "points": POINTS, "sides": SIDES,
                          "vertices": verts, "baseline": "geometry nodes Curve to Mesh (evaluation)",
                          "baseline_vertices": gn_verts, "seconds": round(ours, 3),
                          "baseline_seconds": round(gn_eval, 3), "speed_ratio": round(gn_eval / ours, 2)}))
    print(json.dumps(operator_case(bpy, ob)))
    print(json.dumps(huge_pages_case(bpy, ob)))
    print(json.dumps(fresh_case()))
    gn_copy = min(geometry_nodes(bpy, ob, copy_mesh=True)[0])
    write, _ = write_case(bpy, pts)
    print(json.dumps({"case": "mesh_write", "seconds": round(write, 3),
                      "baseline": "Curve to Mesh evaluation + copy of its mesh into a new object",
                      "baseline_seconds": round(gn_copy, 3), "speed_ratio": round(gn_copy / write, 2)}))
    print(json.dumps(preview_case(pts)))
    print(json.dumps(memory_case()))


if __name__ == "__main__":
    main()

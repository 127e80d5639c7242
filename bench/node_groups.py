"""Tessera's geometry-nodes groups against the nearest built-in and the operator, in one run.

- ``<phong|pn>_group``: the "Tessera Phong" / "Tessera PN Triangles" group evaluated as a modifier on a smooth
  Suzanne (968 triangles, Level 4 and 5) against Subdivision Surface evaluated at level 5 on the same object,
  output triangles per second (a quad counts as two triangles); and against ``tessera.tessellate`` (the same
  method, end to end, a new object) at about the same output.
- ``tubes_group``: the "Tessera Tubes" group on a Curve object of CURVES poly splines of POINTS points (random
  walks, radius per point), 8 sides, no caps, against Curve to Mesh with an 8-point Curve Circle profile scaled by
  the radius (Blender's own sweep, its minimum-twist frames, no UVs), with and without the group's UVs, and
  against ``tessera.tubes`` end to end; output quads per second.
- ``terrain_group``: the "Tessera Terrain" group on a TERRAIN² float height map (synthetic ridges, tiles of 32,
  distance levels for a camera over one corner) against ``tessera.terrain_bake`` with the same levels (Distance
  Only, powers of two, no culling) re-meshing the same map for the same camera, and against Blender's nearest
  built-in: a Grid of the map's full resolution with a Displace modifier (image texture on its UVs) evaluated;
  output triangles per second, and the wall-clock ratio (the level of detail's point: fewer triangles).
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
    evaluated = ob.evaluated_get(depsgraph)
    if hasattr(evaluated.data, "polygons"):
        len(evaluated.data.polygons)  # a subdivided mesh is made when it is first read (GPU subdivision defers it)
    seconds = time.perf_counter() - t
    me = evaluated.to_mesh()
    n = len(me.loops) - 2 * len(me.polygons)  # triangles: a k-gon counts k - 2
    evaluated.to_mesh_clear()
    return seconds, n


def run_operator(bpy, ob, call):
    """Seconds an operator ``call`` takes on the active ``ob`` and the faces of the object it makes (removed)."""
    bpy.context.view_layer.objects.active = ob
    t = time.perf_counter()
    call()
    seconds = time.perf_counter() - t
    out = bpy.context.active_object
    faces, me = len(out.data.polygons), out.data
    bpy.data.objects.remove(out)
    bpy.data.meshes.remove(me)
    return seconds, faces


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
    bpy.data.objects.remove(ob)
    spec = importlib.import_module(f"{name}.addon.tubes.nodes").SPEC
    run_tubes(bpy, groups, spec, random_walks(bpy, CURVES, POINTS))
    synth = importlib.import_module("tessera.tools.ridged_terrain")
    run_terrain(bpy, groups, importlib.import_module(f"{name}.addon.terrain.nodes").SPEC, synth)


TERRAIN, TILE, TEXEL, HEIGHT, FULL_DETAIL = 1025, 32, 1.0, 150.0, 250.0


def run_terrain(bpy, groups, spec, synth):
    """The terrain group against terrain_bake and a displaced full-resolution grid: prints two JSON rows."""
    import numpy as np

    heights = np.asarray(synth.ridged_terrain(TERRAIN, seed=7), np.float32)
    image = bpy.data.images.new("Bench Heights", TERRAIN, TERRAIN, float_buffer=True, is_data=True)
    image.pixels.foreach_set(np.repeat(heights.ravel(), 4))
    cam = bpy.data.objects.new("Bench Camera", bpy.data.cameras.new("Bench Camera"))
    bpy.context.scene.collection.objects.link(cam)
    cam.location, cam.rotation_euler = (-450.0, -450.0, 220.0), (1.15, 0.0, -0.785)
    bpy.context.scene.camera = cam
    group_ob = bpy.data.objects.new("Terrain Group", bpy.data.meshes.new("Terrain Group"))
    bpy.context.scene.collection.objects.link(group_ob)
    inputs = {"Image": image, "Texel Size": TEXEL, "Height Scale": HEIGHT, "Tile Size": TILE,
              "Detail Distance": FULL_DETAIL}
    bpy.ops.tessera.terrain_add(source="IMAGE", image_name=image.name, texel_size=TEXEL, height_scale=HEIGHT,
                                tile_size=TILE, mode="DISTANCE", d_max=FULL_DETAIL, levels="POW2", culling=False)
    baked = bpy.context.active_object
    baked.location = (0.0, 0.0, 0.0)
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=TERRAIN - 1, y_subdivisions=TERRAIN - 1,
                                    size=TEXEL * (TERRAIN - 1), location=(0.0, 0.0, 0.0))
    grid = bpy.context.active_object
    texture = bpy.data.textures.new("Bench Heights", "IMAGE")
    texture.image = image
    best = {"group": float("inf"), "operator": float("inf"), "displace": float("inf")}
    counts = {}
    for _ in range(REPEAT):
        mod = group_ob.modifiers.new("Terrain", "NODES")
        mod.node_group = groups.ensure_group(spec)
        seconds, counts["group"] = evaluate(bpy, group_ob, mod, lambda m: groups.set_inputs(m, inputs))
        best["group"] = min(best["group"], seconds)
        group_ob.modifiers.remove(mod)
        bpy.context.view_layer.objects.active = baked
        t = time.perf_counter()
        bpy.ops.tessera.terrain_bake()
        best["operator"] = min(best["operator"], time.perf_counter() - t)
        counts["operator"] = len(baked.data.loops) - 2 * len(baked.data.polygons)
        mod = grid.modifiers.new("Displace", "DISPLACE")

        def displace(m):
            m.texture, m.texture_coords, m.strength, m.mid_level = texture, "UV", HEIGHT, 0.0
        seconds, counts["displace"] = evaluate(bpy, grid, mod, displace)
        best["displace"] = min(best["displace"], seconds)
        grid.modifiers.remove(mod)
    rate = {k: counts[k] / best[k] for k in best}
    for base, label in (("operator", "tessera.terrain_bake (Distance Only, powers of two, no culling), same camera"),
                        ("displace", f"Grid {TERRAIN}x{TERRAIN} + Displace modifier (image on UVs) evaluation")):
        print(json.dumps({"bench": "node_groups", "case": f"terrain_group_{TERRAIN}_vs_{base}",
                          "output_triangles": counts["group"], "seconds": round(best["group"], 4),
                          "triangles_per_second": round(rate["group"]), "baseline": label,
                          "baseline_triangles": counts[base], "baseline_seconds": round(best[base], 4),
                          "baseline_triangles_per_second": round(rate[base]),
                          "speedup": round(rate["group"] / rate[base], 2),
                          "wall_clock_speedup": round(best[base] / best["group"], 2)}), flush=True)


CURVES, POINTS, SIDES = 3000, 40, 8


def random_walks(bpy, count, points):
    """A Curve object of ``count`` POLY splines of ``points`` points each."""
    import numpy as np

    rng = np.random.default_rng(7)
    data = bpy.data.curves.new("Walks", "CURVE")
    data.dimensions = "3D"
    for _ in range(count):
        s = data.splines.new("POLY")
        s.points.add(points - 1)
        walk = np.cumsum(rng.normal(size=(points, 3)) * 0.05, axis=0) + rng.uniform(-5, 5, 3)
        s.points.foreach_set("co", np.c_[walk, np.ones(points)].ravel())
        s.points.foreach_set("radius", rng.uniform(0.5, 1.5, points))
    ob = bpy.data.objects.new("Walks", data)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def curve_to_mesh_group(bpy):
    """Blender's own sweep: Curve to Mesh with a Curve Circle of SIDES points, scaled by the curve radius."""
    tree = bpy.data.node_groups.new("Curve to Mesh baseline", "GeometryNodeTree")
    tree.interface.new_socket("Curve", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Mesh", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    gi, go = tree.nodes.new("NodeGroupInput"), tree.nodes.new("NodeGroupOutput")
    circle = tree.nodes.new("GeometryNodeCurvePrimitiveCircle")
    circle.mode = "RADIUS"
    circle.inputs["Resolution"].default_value = SIDES
    circle.inputs["Radius"].default_value = 0.02
    sweep = tree.nodes.new("GeometryNodeCurveToMesh")
    tree.links.new(gi.outputs[0], sweep.inputs["Curve"])
    tree.links.new(circle.outputs[0], sweep.inputs["Profile Curve"])
    if "Scale" in sweep.inputs:
        tree.links.new(tree.nodes.new("GeometryNodeInputRadius").outputs[0], sweep.inputs["Scale"])
    tree.links.new(sweep.outputs[0], go.inputs[0])
    return tree


def run_tubes(bpy, groups, spec, ob):
    """The tubes group against Curve to Mesh and tessera.tubes: prints two JSON rows."""
    best = {"group": float("inf"), "group_no_uv": float("inf"), "curve_to_mesh": float("inf"),
            "operator": float("inf")}
    counts = {}
    baseline = curve_to_mesh_group(bpy)
    tree = groups.ensure_group(spec)
    trees = {"group": tree, "group_no_uv": tree, "curve_to_mesh": baseline}
    inputs = {"group": {"Radius": 0.02, "Sides": SIDES}, "group_no_uv": {"Radius": 0.02, "Sides": SIDES, "UV Map": ""},
              "curve_to_mesh": {}}
    for _ in range(REPEAT):
        for key, tree in trees.items():
            mod = ob.modifiers.new(key, "NODES")
            mod.node_group = tree
            seconds, triangles = evaluate(bpy, ob, mod, lambda m, key=key: groups.set_inputs(m, inputs[key]))
            counts[key] = triangles // 2
            best[key] = min(best[key], seconds)
            ob.modifiers.remove(mod)
        for other in bpy.context.selected_objects:
            other.select_set(False)
        ob.select_set(True)
        seconds, counts["operator"] = run_operator(bpy, ob, lambda: bpy.ops.tessera.tubes(
            radius=0.02, sides=SIDES, caps="NONE"))
        best["operator"] = min(best["operator"], seconds)
    rate = {k: counts[k] / best[k] for k in best}
    for ours, base, label in (("group", "curve_to_mesh", f"Curve to Mesh, {SIDES}-point circle scaled by the radius"),
                              ("group_no_uv", "curve_to_mesh", "the same, the group writing no UVs"),
                              ("group", "operator", "tessera.tubes end to end (with UVs)")):
        print(json.dumps({"bench": "node_groups", "case": f"tubes_{ours}_{CURVES}x{POINTS}_vs_{base}",
                          "output_quads": counts[ours], "seconds": round(best[ours], 4),
                          "quads_per_second": round(rate[ours]), "baseline": label,
                          "baseline_quads": counts[base], "baseline_seconds": round(best[base], 4),
                          "baseline_quads_per_second": round(rate[base]),
                          "speedup": round(rate[ours] / rate[base], 2)}), flush=True)


def run(bpy, ob, groups, spec, method, level):
    """One group at one level against its baselines: prints two JSON rows."""
    best = {"group": float("inf"), "subsurf": float("inf"), "operator": float("inf")}
    counts = {}
    for _ in range(REPEAT):
        mod = ob.modifiers.new(spec.name, "NODES")
        mod.node_group = groups.ensure_group(spec)
        seconds, counts["group"] = evaluate(bpy, ob, mod,
                                            lambda m, lv=level: groups.set_inputs(m, {"Subdivisions": lv}))
        best["group"] = min(best["group"], seconds)
        ob.modifiers.remove(mod)
        mod = ob.modifiers.new("Subsurf", "SUBSURF")
        seconds, counts["subsurf"] = evaluate(bpy, ob, mod, lambda m: setattr(m, "levels", 5))
        best["subsurf"] = min(best["subsurf"], seconds)
        ob.modifiers.remove(mod)
        tess_level = 14 if level == 4 else 28  # 968 * floor(3 L^2 / 2) triangles: about the group's output
        seconds, counts["operator"] = run_operator(bpy, ob, lambda lv=tess_level: bpy.ops.tessera.tessellate(
            method=method, level=lv))
        best["operator"] = min(best["operator"], seconds)
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

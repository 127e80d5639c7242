"""One-point parametric surfaces: [Nunes 2011]'s Tables 2.1 / 2.2 ([Nunes 2011, §2.4]), here.

N tori of 8,192 triangles (factor 64, integer partitioning: 2F²), scattered in a cube, drawn into a 256x256
offscreen with depth test, in the same run:

- ``one_point``: the GPU path: N control points (one RGBA32F texel each) and the factor-64 pattern, the torus
  evaluated in the vertex shader, one instanced draw;
- ``mesh``: the same tori computed on the CPU (`kernels.surfaces.domain_mesh.instance_positions`) and uploaded as
  one vertex buffer, drawn in one call. As in [Nunes 2011], non-indexed float3 positions: every triangle's three
  corners ([Nunes 2011]'s "CPU tori in one vertex buffer"); what is uploaded is measured from the arrays handed to the
  batch (positions, and the constant normals the flat-mesh shader takes: twice [Nunes 2011]'s 12 bytes a vertex).
  Both are drawn unlit, a flat colour, as [Nunes 2011]'s position-only vertices (the one-point shader then skips its
  four extra evaluations for the normal). Built while it fits the memory of this machine (``MESH_LIMIT_BYTES``);
  beyond, only the analytic bytes.

Per N: bytes (Table 2.2's accounting, and measured), frame time (draw + a one-pixel read back, so the GPU's work
is included; ``mesh_upload_draw_ms`` adds building the buffer and its upload, what a changed surface costs), and
their ratios. On a CPU-only machine the renderer is Mesa llvmpipe, a software rasteriser: absolute times are not
a GPU's; the device tool runs the same on a real GPU where one is lent.
- ``teapot``: *Tessellate Surface* (``tessera.surface_tessellate``, curvature levels) on the teapot's body of
  revolution (24 bicubic patches as a surface object) end to end, against Blender's own conversion of the same
  surface object to a mesh (its evaluation at a resolution giving about the same triangles, copied into a new mesh
  object), triangles per second.
Run: .venv/bin/python bench/surfaces.py [--full]   (--full: N up to 20,000; else up to 2,500)
"""

import importlib
import json
import sys

import numpy as np
from _setup import enable_extension, offscreen_frame, seconds

SIZE = 256
FACTOR = 64
COUNTS = (1, 10, 100, 500, 1000, 2500, 5000, 10000, 20000)
MESH_LIMIT_BYTES = 1 << 30  # 1 GiB of positions at most for the uploaded-mesh path


def main():
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    package = enable_extension()
    mod = lambda name: importlib.import_module(f"{package}.{name}")  # noqa: E731
    import gpu
    from gpu_extras.batch import batch_for_shader

    renderer = mod("addon.gpu_context").ensure_gpu_context()
    parametric, domain_mesh = mod("kernels.surfaces.parametric"), mod("kernels.surfaces.domain_mesh")
    draw, offscreen, loader = mod("gpu_shaders.surfaces.draw"), mod("gpu_shaders.offscreen"), mod("gpu_shaders.loader")
    camera = mod("kernels.common.camera")
    torus = parametric.Torus()
    vp = camera.look_at((60.0, -80.0, 50.0), (0, 0, 0), fov_deg=40, far=1000.0)
    box = gpu.types.GPUOffScreen(SIZE, SIZE)
    shader = loader.shader("flat_mesh", offscreen._describe_flat_mesh)
    print(json.dumps({"bench": "surfaces", "case": "renderer", "renderer": renderer,
                      "backend": gpu.platform.backend_type_get(), "triangles_per_torus": 2 * FACTOR * FACTOR}))

    frame = offscreen_frame(box, SIZE, SIZE)

    run_teapot(bpy, mod)
    counts = COUNTS if "--full" in sys.argv else COUNTS[:6]
    uv, tris = domain_mesh.domain_pattern(FACTOR)
    for n in counts:
        points = np.random.default_rng(n).uniform(-40, 40, (n, 3))
        mesh_bytes, point_bytes = domain_mesh.upload_bytes(n, FACTOR)
        row = {"bench": "surfaces", "case": f"tori_{n}", "tori": n, "triangles": n * 2 * FACTOR * FACTOR,
               "analytic_mesh_bytes": mesh_bytes, "analytic_one_point_bytes": point_bytes,
               "analytic_ratio": mesh_bytes / point_bytes}
        data = draw.SurfaceDrawData(torus, points, FACTOR)
        row["one_point_bytes"] = data.uploaded_bytes
        row["one_point_draw_ms"] = 1e3 * seconds(lambda data=data: frame(lambda: data.draw(vp, lit=False)))
        row["one_point_upload_draw_ms"] = 1e3 * seconds(lambda points=points: frame(
            lambda: draw.SurfaceDrawData(torus, points, FACTOR).draw(vp, lit=False)), repeat=2)
        if mesh_bytes <= MESH_LIMIT_BYTES:
            def upload(points=points, n=n):
                corners = domain_mesh.instance_positions(torus, FACTOR, points).reshape(n, -1, 3)[:, tris]
                pos = np.ascontiguousarray(corners.reshape(-1, 3))
                normals = np.zeros_like(pos)
                normals[:, 2] = 1.0
                return batch_for_shader(shader, "TRIS", {"pos": pos, "nor": normals}), pos.nbytes + normals.nbytes

            resident, pos_bytes = upload()

            def draw_mesh(batch):
                offscreen.set_shading(shader, vp, (0.8, 0.8, 0.8, 1.0), False)
                batch.draw(shader)

            row["mesh_bytes"] = pos_bytes
            row["mesh_draw_ms"] = 1e3 * seconds(lambda resident=resident: frame(lambda: draw_mesh(resident)))
            row["mesh_upload_draw_ms"] = 1e3 * seconds(lambda: frame(lambda: draw_mesh(upload()[0])), repeat=2)
            row["mesh_over_one_point_bytes"] = pos_bytes / data.uploaded_bytes
            row["mesh_over_one_point_draw"] = row["mesh_draw_ms"] / row["one_point_draw_ms"]
            row["mesh_upload_over_one_point_upload"] = row["mesh_upload_draw_ms"] / row["one_point_upload_draw_ms"]
            del resident
        print(json.dumps(row), flush=True)
    box.free()


def run_teapot(bpy, mod):
    nets, _ = mod("kernels.surfaces.revolved_teapot").teapot_patches()
    surface = mod("addon.curve_bridge").write_surface_patches(nets)

    def ours():
        bpy.context.view_layer.objects.active = surface
        bpy.ops.tessera.surface_tessellate(metrics={"CURVATURE"})
        out = bpy.context.active_object
        n, data = len(out.data.polygons), out.data
        bpy.data.objects.remove(out)
        bpy.data.meshes.remove(data)
        return n

    def blenders():
        surface.data.update_tag()  # re-evaluate, as a changed surface would
        depsgraph = bpy.context.evaluated_depsgraph_get()
        depsgraph.update()
        me = bpy.data.meshes.new_from_object(surface.evaluated_get(depsgraph))
        ob = bpy.data.objects.new("converted", me)
        bpy.context.scene.collection.objects.link(ob)
        n = sum(len(p.vertices) - 2 for p in me.polygons)
        bpy.data.objects.remove(ob)
        bpy.data.meshes.remove(me)
        return n

    n_ours = ours()

    def blender_count(res):
        surface.data.resolution_u = surface.data.resolution_v = res
        return blenders()

    # the resolution whose triangle count is nearest ours (Blender's resolution counts per control point)
    res = min(range(1, 33), key=lambda r: abs(blender_count(r) - n_ours))
    surface.data.resolution_u = surface.data.resolution_v = res

    n_blender = blenders()
    t_ours, t_blender = seconds(ours, 5), seconds(blenders, 5)
    print(json.dumps({"bench": "surfaces", "case": "teapot_tessellate_surface", "patches": len(nets),
                      "triangles": n_ours, "seconds": round(t_ours, 4),
                      "baseline": f"Blender's surface to mesh (resolution {res}), copied into a new object",
                      "baseline_triangles": n_blender, "baseline_seconds": round(t_blender, 4),
                      "speedup_per_triangle": round((n_ours / t_ours) / (n_blender / t_blender), 2)}), flush=True)
    bpy.data.objects.remove(surface)


if __name__ == "__main__":
    main()

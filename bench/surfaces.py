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
- ``tessellate_surface_*``: *Tessellate Surface* (``tessera.surface_tessellate`` at a Tolerance of 2e-4 of the
  model's size) end to end (read the splines, split them into patches, choose and check the levels, evaluate, write
  the mesh) on Blender's NURBS sphere and torus and Newell's teapot (32 patches), against Blender's own conversion of
  the same surface object to a mesh copied into a new object, at the lowest resolution whose mesh is as close to the
  surface (both measured the same way: each triangle at 7 points against the surface at the same parameters):
  triangles and seconds over the baseline's, and triangles per second; where the triangles were measured (the
  OpenCL device, `kernels.surfaces.patch_deviation_opencl`, or numpy), and the same operator's seconds with OpenCL
  off (numpy measuring) over them.
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

    for name, make in surface_models(bpy, mod):
        run_tessellate_surface(bpy, mod, name, make)
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


#: The tolerance of the Tessellate Surface cases, as a fraction of each model's size.
RELATIVE_TOLERANCE = 2e-4
#: Timed runs of each side of a Tessellate Surface case (the shortest counts): a shared machine's times vary.
REPEAT = 9
BARY = np.array([[.5, .5, 0], [0, .5, .5], [.5, 0, .5], [1 / 3, 1 / 3, 1 / 3], [2 / 3, 1 / 6, 1 / 6],
                 [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]])


def blender_deviation(mod, surface, me):
    """The largest distance between Blender's conversion of ``surface`` and the surface, measured as Tessera's
    meshes are (each triangle at 7 barycentric points against the surface at the same point of its corners'
    parameters): Blender evaluates each spline on a grid of resolution x points equal steps a direction (v fastest);
    each grid quad is taken at its better diagonal, a quad with two corners at one point (a pole) as a triangle."""
    nurbs, bp = mod("kernels.common.curves.nurbs"), mod("kernels.surfaces.bezier_patches")
    pos = np.array([v.co[:] for v in me.vertices], np.float64)
    worst, start = 0.0, 0
    surfaces, _ = mod("addon.curve_bridge").read_surface_splines(surface.data)
    for (_, spline), s in zip(surfaces, surface.data.splines, strict=True):
        ps = nurbs.patches_of([spline])
        n_u, n_v = s.resolution_u * s.point_count_u, s.resolution_v * s.point_count_v
        cu, cv = s.use_cyclic_u, s.use_cyclic_v
        fu, fv = np.linspace(0, 1, n_u + cu)[:n_u], np.linspace(0, 1, n_v + cv)[:n_v]
        grid = pos[start:start + n_u * n_v].reshape(n_u, n_v, 3)
        start += n_u * n_v
        iu, jv = np.arange(n_u - 1 + cu), np.arange(n_v - 1 + cv)
        i0, j0 = np.meshgrid(iu, jv, indexing="ij")
        i1, j1 = (i0 + 1) % n_u, (j0 + 1) % n_v
        corners = [(i0, j0), (i1, j0), (i1, j1), (i0, j1)]
        p = np.stack([grid[i, j] for i, j in corners], 2).reshape(-1, 4, 3)
        # parameters: the wrapped corner of a cyclic direction is 1, not 0
        uu = np.stack([np.where(i == 0, 1.0, fu[i]) if cu else fu[i] for i, _ in corners], 2).reshape(-1, 4)
        uu[:, [0, 3]] = fu[i0.ravel()][:, None]
        vv = np.stack([fv[j] for _, j in corners], 2).reshape(-1, 4)
        vv[:, [2, 3]] = np.where(j1.ravel() == 0, 1.0, fv[j1.ravel()])[:, None]
        st = np.stack([uu, vv], -1)
        best = np.full(len(p), np.inf)
        for tris in (((0, 1, 2), (0, 2, 3)), ((0, 1, 3), (1, 2, 3))):
            dev = np.zeros(len(p))
            for tri in tris:
                tp, tuv = p[:, tri].copy(), st[:, tri].copy()
                for a, b in ((0, 1), (1, 2), (0, 2)):  # two corners at one point: a pole; its parameter halfway
                    same = np.all(tp[:, a] == tp[:, b], axis=1)
                    mid = 0.5 * (tuv[same, a] + tuv[same, b])
                    tuv[same, a] = tuv[same, b] = mid
                flat = np.all(tp[:, 0] == tp[:, 1], 1) | np.all(tp[:, 1] == tp[:, 2], 1) | np.all(
                    tp[:, 0] == tp[:, 2], 1)
                on_mesh = np.einsum("sc,tcd->tsd", BARY, tp)
                at = np.einsum("sc,tcd->tsd", BARY, tuv)
                q, local = ps.locate(at.reshape(-1, 2))
                on = bp.evaluate(ps.patches[q], local[:, :1], local[:, 1:])
                d = np.linalg.norm(on.reshape(on_mesh.shape) - on_mesh, axis=-1).max(axis=1)
                dev = np.maximum(dev, np.where(flat, 0.0, d))
            best = np.minimum(best, dev)
        worst = max(worst, float(best.max()))
    return worst


def run_tessellate_surface(bpy, mod, name, make):
    """*Tessellate Surface* at a tolerance, end to end, against Blender's own conversion of the same surface object
    at the lowest resolution whose mesh is as close to the surface (measured the same way)."""
    surface = make()
    size = float(np.abs(np.array([v[:] for v in surface.bound_box])).max())
    tol = RELATIVE_TOLERANCE * size
    kw = dict(metrics={"TOLERANCE"}, tolerance=tol, max_level=64)

    def ours():
        bpy.context.view_layer.objects.active = surface
        assert bpy.ops.tessera.surface_tessellate(**kw) == {"FINISHED"}
        out = bpy.context.active_object
        n, data = len(out.data.polygons), out.data
        bpy.data.objects.remove(out)
        bpy.data.meshes.remove(data)
        return n

    def converted():
        surface.data.update_tag()  # re-evaluate, as a changed surface would
        depsgraph = bpy.context.evaluated_depsgraph_get()
        depsgraph.update()
        return bpy.data.meshes.new_from_object(surface.evaluated_get(depsgraph))

    def blenders():
        me = converted()
        ob = bpy.data.objects.new("converted", me)
        bpy.context.scene.collection.objects.link(ob)
        n = sum(len(p.vertices) - 2 for p in me.polygons)
        bpy.data.objects.remove(ob)
        bpy.data.meshes.remove(me)
        return n

    n_ours = ours()
    nurbs, bp = mod("kernels.common.curves.nurbs"), mod("kernels.surfaces.bezier_patches")
    surfaces, _ = mod("addon.curve_bridge").read_surface_splines(surface.data)
    result = bp.tessellate_surface(nurbs.patches_of([s for _, s in surfaces]).patches,
                           bp.PatchLod(metrics=("TOLERANCE",), tolerance=tol, max_level=64))
    ours_dev = float(result.deviation.max())
    res, dev = 0, np.inf
    while dev > ours_dev and res < 128:  # the lowest resolution as close to the surface as ours
        res += 1
        for s in surface.data.splines:
            s.resolution_u = s.resolution_v = res
        me = converted()
        dev = blender_deviation(mod, surface, me)
        bpy.data.meshes.remove(me)
    n_blender = blenders()
    t_ours, t_blender = seconds(ours, REPEAT), seconds(blenders, REPEAT)
    # the same operator with its triangles measured by numpy (OpenCL off), in the same run
    ocl = mod("kernels.common.opencl_runtime")
    runtime, mode = ocl.get_runtime(), ocl.current_mode()
    measured_on = runtime.description if mod("kernels.surfaces.patch_deviation_opencl").supports(runtime) else "numpy"
    ocl.configure(mode="0")
    try:
        t_numpy = seconds(ours, REPEAT)
    finally:
        ocl.configure(mode=mode)
    print(json.dumps({"bench": "surfaces", "case": f"tessellate_surface_{name}", "patches": len(result.inner_levels),
                      "tolerance": round(tol, 6), "triangles": n_ours, "deviation": round(ours_dev, 6),
                      "seconds": round(t_ours, 4),
                      "baseline": f"Blender's surface to mesh at resolution {res}, copied into a new object",
                      "baseline_triangles": n_blender, "baseline_deviation": round(dev, 6),
                      "baseline_seconds": round(t_blender, 4),
                      "triangles_over_baseline": round(n_ours / n_blender, 3),
                      "seconds_over_baseline": round(t_ours / t_blender, 2),
                      "speedup_per_triangle": round((n_ours / t_ours) / (n_blender / t_blender), 2),
                      "measured_on": measured_on, "numpy_seconds": round(t_numpy, 4),
                      "numpy_over_measured_on": round(t_numpy / t_ours, 2)}), flush=True)
    bpy.data.objects.remove(surface)


def surface_models(bpy, mod):
    """(name, maker) of the Tessellate Surface cases: Blender's NURBS sphere and torus as Add › Surface makes
    them, and Newell's full teapot (32 patches) as a surface object."""

    def primitive(kind):
        def make():
            getattr(bpy.ops.surface, f"primitive_nurbs_surface_{kind}_add")()
            return bpy.context.active_object
        return make

    def teapot():
        from tessera.tools.surface_objects import write_surface_patches
        from tessera.tools.utah_teapot import teapot_patches

        nets, _ = teapot_patches()
        return write_surface_patches(nets)

    return (("sphere", primitive("sphere")), ("torus", primitive("torus")), ("teapot", teapot))


if __name__ == "__main__":
    main()

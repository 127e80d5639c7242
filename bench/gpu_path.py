"""GPU path: preview frame time and bytes sent to the GPU, against drawing the applied (tessellated) mesh.

Base mesh: Suzanne, linearly refined to 23,232 triangles; PN at uniform levels giving about 0.14M, 1.25M, 5M and
(``--full``) 20M output triangles, 512x512 offscreen, smooth-lit.

Per size, in the same run:

- ``preview_draw_ms``: one preview frame (instanced patterns, surface evaluated in the vertex shader), levels
  unchanged; ``preview_relevel_ms``: a frame whose levels changed (new instance textures + draw).
- ``mesh_draw_ms``: drawing the applied mesh already on the GPU; ``mesh_upload_draw_ms``: uploading it (a batch
  of positions, normals and indices, as a mesh edit or a re-tessellation must) and drawing it.
- bytes: ``preview_control_bytes`` once per mesh edit, ``preview_level_bytes`` per level change, against
  ``mesh_bytes`` (float32 positions and normals, int32 indices): [Nunes 2011]'s Tables 2.2 / 4.2 argument.

Frame times end with a one-pixel read back, so they include the GPU's work. The renderer string is recorded
(Mesa llvmpipe on CPU-only machines: a software rasteriser, so absolute times are not a GPU's).
Run: .venv/bin/python bench/gpu_path.py [--full]
"""

import importlib
import json
import sys

import numpy as np
from _setup import enable_extension, offscreen_frame, seconds

WIDTH = HEIGHT = 512
LEVELS = (2, 6, 12, 24)


def measure(mod, base, level, vp, frame):
    """One output size: preview and applied-mesh frames and bytes (see the module docstring)."""
    from gpu_extras.batch import batch_for_shader

    tess = mod("kernels.tessellation.tessellate")
    preview, offscreen = mod("gpu_shaders.tessellation.draw"), mod("gpu_shaders.offscreen")
    edge = tess.uniform_levels(base, level)
    inputs = tess.surface_inputs(base, edge, "PN", tess.SurfaceOptions())
    data = preview.PatchDrawData(inputs, "PN")
    data.set_levels(inputs.edge_levels)
    out = tess.tessellate(base, edge, method="PN").mesh
    shader = mod("gpu_shaders.loader").shader("flat_mesh", offscreen._describe_flat_mesh)
    pos, nor, idx = out.positions, out.point_normals.astype(np.float32), out.triangles.astype(np.int32)

    def upload():
        return batch_for_shader(shader, "TRIS", {"pos": pos, "nor": nor}, indices=idx)

    resident = upload()

    def draw_mesh(batch):
        offscreen.set_shading(shader, vp, (0.8, 0.8, 0.8, 1.0), True)
        batch.draw(shader)

    def relevel():
        data.set_levels(inputs.edge_levels)
        frame(lambda: data.draw(vp))

    row = {"case": "frame", "output_triangles": len(out.triangles), "level": level,
           "preview_draw_ms": 1e3 * seconds(lambda: frame(lambda: data.draw(vp))),
           "preview_relevel_ms": 1e3 * seconds(relevel),
           "mesh_draw_ms": 1e3 * seconds(lambda: frame(lambda: draw_mesh(resident))),
           "mesh_upload_draw_ms": 1e3 * seconds(lambda: frame(lambda: draw_mesh(upload()))),
           "preview_control_bytes": data.control_bytes, "preview_level_bytes": data.instance_bytes,
           "mesh_bytes": pos.nbytes + nor.nbytes + idx.nbytes}
    row["mesh_over_preview_bytes"] = row["mesh_bytes"] / (row["preview_control_bytes"] + row["preview_level_bytes"])
    row["preview_over_mesh_draw"] = row["preview_draw_ms"] / row["mesh_draw_ms"]
    row["preview_relevel_over_mesh_upload"] = row["preview_relevel_ms"] / row["mesh_upload_draw_ms"]
    return row


def main():
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    package = enable_extension()
    mod = lambda name: importlib.import_module(f"{package}.{name}")  # noqa: E731
    import gpu

    renderer = mod("addon.gpu_context").ensure_gpu_context()
    tess, camera = mod("kernels.tessellation.tessellate"), mod("kernels.common.camera")
    bpy.ops.mesh.primitive_monkey_add()
    ob = bpy.context.active_object
    for poly in ob.data.polygons:
        poly.use_smooth = True
    arrays, _ = mod("addon.bridge").read_mesh(ob.data)
    base = tess.tessellate(arrays, tess.uniform_levels(arrays, 4), method="LINEAR").mesh
    base.corner_normals = None
    vp = camera.look_at((2.2, -2.6, 1.4), (0, 0, 0), fov_deg=40)
    fb_box = gpu.types.GPUOffScreen(WIDTH, HEIGHT)
    print(json.dumps({"case": "renderer", "renderer": renderer, "backend": gpu.platform.backend_type_get(),
                      "base_triangles": len(base.triangles)}))
    levels = LEVELS if "--full" in sys.argv else LEVELS[:-1]

    frame = offscreen_frame(fb_box, WIDTH, HEIGHT)

    for level in levels:
        print(json.dumps(measure(mod, base, level, vp, frame)), flush=True)
    fb_box.free()


if __name__ == "__main__":
    main()

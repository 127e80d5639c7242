"""Vector Field Texture end to end (``tessera.vector_field_texture``: seeds, advection, splats, the packed float image),
its GPU path against its numpy path in the same run, on the ABC flow and a 64 x 64 grid mesh's field.

Blender has no tool that draws a texture along a flow, so the baseline is the operator's own numpy reference (what
*Evaluate On: CPU* runs and what the GPU path falls back to). Per size and seed lattice: the seconds of each (best of
3, the image removed after each call, untimed), and CPU over GPU. On a CPU-only machine the "GPU" is Mesa llvmpipe,
a software rasteriser; the device tool runs the same on a real GPU where one is lent.
Run: .venv/bin/python bench/vector_field.py
"""

import json
import time

import numpy as np
from _setup import enable_extension

#: (texture side, seeds per side): the default's seeds, and the densest lattice a near camera gives (4 times)
CASES = ((256, 160), (512, 160), (1024, 160), (1024, 640))
STEPS, STEP = 60, 0.002


def _grid(bpy):
    """A 64 x 64 grid mesh with a swirl in its ``velocity`` point attribute (what a simulation would leave)."""
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=63, y_subdivisions=63, size=2)
    ob = bpy.context.active_object
    co = np.array([v.co for v in ob.data.vertices])
    attr = ob.data.attributes.new("velocity", "FLOAT_VECTOR", "POINT")
    swirl = np.c_[-co[:, 1], co[:, 0] + 0.3 * np.sin(3 * co[:, 1]), np.zeros(len(co))]
    attr.data.foreach_set("vector", swirl.astype(np.float32).ravel())
    return ob.name


def _seconds(bpy, **kw):
    best = float("inf")
    for _ in range(3):
        before = set(bpy.data.images)
        t = time.perf_counter()
        if bpy.ops.tessera.vector_field_texture(**kw) != {"FINISHED"}:
            raise RuntimeError(f"vector_field_texture({kw}) did not finish")
        best = min(best, time.perf_counter() - t)
        for image in set(bpy.data.images) - before:
            bpy.data.images.remove(image)
    return best


def main():
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    package = enable_extension()
    import importlib

    renderer = importlib.import_module(f"{package}.addon.gpu_context").ensure_gpu_context()
    grid = _grid(bpy)
    for field, extra in (("ABC", {}), ("MESH", {"field_object": grid})):
        for size, seeds in CASES:
            kw = dict(field=field, width=size, height=size, seeds=seeds, steps=STEPS, step=STEP, **extra)
            gpu = _seconds(bpy, backend="GPU", **kw)
            cpu = _seconds(bpy, backend="CPU", **kw)
            row = {"bench": "vector_field", "case": f"{field.lower()}_{size}_{seeds}", "pixels": size * size,
                   "seeds": seeds * seeds, "steps": STEPS, "renderer": str(renderer), "gpu_seconds": round(gpu, 4),
                   "baseline": "the same operator on the CPU (numpy)", "cpu_seconds": round(cpu, 4),
                   "cpu_over_gpu": round(cpu / gpu, 2)}
            print(json.dumps(row), flush=True)


main()

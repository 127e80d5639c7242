"""One SHA-256 per kernel family over the bytes of its outputs on fixed inputs (numpy backend).

`make test-all` runs this in every Blender's environment (NumPy 1.26 on Python 3.11, NumPy 2.x on 3.13) and fails
when two environments disagree: the kernels must give the same bytes whatever NumPy they run on.

Usage: python tools/kernel_digest.py   (prints one JSON object: family -> hex digest)
"""

import hashlib
import json

import numpy as np
from source_tree import as_package  # tools/ is first on sys.path


def _digest(*arrays):
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(f"{a.dtype.str}{a.shape}".encode())
        h.update(a.tobytes())
    return h.hexdigest()


def tessellation():
    from tessera.kernels.common.mesh_arrays import MeshArrays
    from tessera.kernels.tessellation.tessellate import tessellate, uniform_levels
    from tessera.tools.generators import random_closed

    v, f = random_closed(3, major=12, minor=8)
    n = v / np.linalg.norm(v, axis=1, keepdims=True)
    mesh = MeshArrays(v, f, point_normals=n.astype(np.float32))
    base = uniform_levels(mesh, 3.0)
    levels = base + np.random.default_rng(1).random(len(base)) * 4
    out = []
    for method in ("PN", "PHONG"):
        for spacing in ("EQUAL", "FRACTIONAL_EVEN"):
            t = tessellate(mesh, levels, spacing=spacing, method=method, backend="numpy").mesh
            out += [t.positions, t.triangles, t.corner_normals if t.corner_normals is not None else t.point_normals]
    return _digest(*out)


def tubes():
    from tessera.kernels.tubes.builder import TubeSettings, build_tubes
    from tessera.kernels.tubes.polylines import Polylines

    rng = np.random.default_rng(5)
    pts = np.cumsum(rng.normal(size=(40 * 12, 3)), axis=0).astype(np.float32)
    lines = Polylines.build(pts, np.arange(0, 40 * 12 + 1, 12), radius=0.1)
    out = []
    for caps in ("NONE", "ROUND"):
        m = build_tubes(lines, TubeSettings(sides=7, caps=caps, uvs=True), backend="numpy")
        out += [np.asarray(getattr(m, name)) for name in ("positions", "normals", "uvs") if getattr(m, name, None)
                is not None]
    return _digest(*out)


def terrain():
    from tessera.kernels.common.camera import Camera
    from tessera.kernels.terrain import heightmap_io as hio
    from tessera.kernels.terrain.analysis import tile_table
    from tessera.kernels.terrain.lod import TerrainLod, select
    from tessera.kernels.terrain.mesh import bake
    from tessera.tools.ridged_terrain import ridged_terrain

    hm = hio.from_array(ridged_terrain(129, seed=2), texel_size=2.0, scale=60.0)
    table = tile_table(hm, 16, backend="numpy")
    cam = Camera.looking_at((10.0, -150.0, 90.0), (0.0, 0.0, 10.0), far=1e4)
    out = []
    for levels in ("POW2", "FRACTIONAL"):
        sel = select(hm, table, cam, TerrainLod(levels=levels))
        m = bake(hm, table, sel)
        out += [sel.edge, sel.inner, m.positions, m.triangles]
    return _digest(*out)


def subdivision():
    from tessera.kernels.subdivision.loop import loop_subdivide
    from tessera.kernels.subdivision.loop_topology import coarse_level
    from tessera.tools.generators import cup, random_irregular_closed

    out = []
    for v, f in (random_irregular_closed(3), cup()):
        edges = coarse_level(f, len(v)).edges
        creases = edges[::4], np.array([10.0, 0.5, 1.7, 2.5] * len(edges))[: len(edges[::4])].astype(np.float32)
        uv = np.random.default_rng(2).random((len(f), 3, 2))
        r = loop_subdivide(v, f, 3, creases=creases, corner_data={"UV": uv}, backend="numpy")
        out += [r.positions, r.triangles, r.edges, r.corner_attributes["UV"]]
    return _digest(*out)


def main():
    as_package("tessera-digest-")
    print(json.dumps({"numpy": np.__version__, "tessellation": tessellation(), "tubes": tubes(),
                      "terrain": terrain(), "subdivision": subdivision()}))


if __name__ == "__main__":
    main()

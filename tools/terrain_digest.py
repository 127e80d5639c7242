"""Check that machines of a render farm mesh terrain blocks alike: prints a digest of the terrain meshes of a synthetic
height map for fixed random cameras (levels chosen, blocks of a split meshed, the bytes of every position and
triangle hashed). Run it on each kind of machine (same Tessera, same Python packages): equal digests mean their farm
tasks weld exactly. Needs only numpy; the source tree is made importable as the package ``tessera``.

Usage: python tools/terrain_digest.py [--cameras N]
"""

import argparse
import hashlib
import json
import platform
from pathlib import Path

from source_tree import as_package  # tools/ is first on sys.path


def digest(cameras=8):
    """{"levels": sha256 of every selection's levels, "meshes": sha256 of every block's mesh} for the fixed cases."""
    import numpy as np
    from tessera.kernels.common.camera import Camera
    from tessera.kernels.terrain import analysis, heightmap_io, lod, mesh
    from tessera.tools.ridged_terrain import ridged_terrain

    hm = heightmap_io.from_array((ridged_terrain(257, seed=11) * 120.0).astype(np.float32), texel_size=3.0)
    table = analysis.tile_table(hm, 16, backend="numpy")
    rng = np.random.default_rng(2026)
    levels, meshes = hashlib.sha256(), hashlib.sha256()
    half = 128 * 3.0
    for k in range(cameras):
        eye = rng.uniform(-2 * half, 2 * half, 3)
        eye[2] = rng.uniform(60.0, 3 * half)
        target = np.append(rng.uniform(-half, half, 2), 20.0)
        cam = Camera.looking_at(eye, target, fov_deg=rng.uniform(25, 70), width=1920, height=1080, far=40 * half)
        settings = lod.TerrainLod(levels=("FRACTIONAL", "POW2", "INTEGER")[k % 3], epsilon=float(rng.uniform(0.5, 4)))
        sel = lod.select(hm, table, cam, settings)
        for a in (sel.h_edges, sel.v_edges, sel.inner, sel.culled):
            levels.update(np.ascontiguousarray(a).tobytes())
        for block in ((0, 0, 2, 2), (1, 0, 2, 2), (0, 1, 2, 2), (1, 1, 2, 2)):
            m = mesh.bake(hm, table, lod.select(hm, table, cam, settings, block=block))
            meshes.update(m.positions.tobytes())
            meshes.update(m.triangles.tobytes())
    return {"levels": levels.hexdigest()[:16], "meshes": meshes.hexdigest()[:16]}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cameras", type=int, default=8)
    args = parser.parse_args()
    as_package("tessera-digest-")
    import numpy as np

    out = digest(args.cameras)
    out.update(machine=platform.processor() or platform.machine(), python=platform.python_version(),
               numpy=np.__version__)
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                out["machine"] = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    print(json.dumps(out))


if __name__ == "__main__":
    main()

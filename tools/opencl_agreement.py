"""How far the OpenCL paths that promise the numpy reference's bytes land from it on this OpenCL device.

For every dab kind of the map kernels (random dabs over 1-, 3- and 4-channel maps, as in the tests) and for the
terrain HAM, counts the float32 values that differ and the largest difference in ulps, once with the runtime's build
options (correctly rounded division and sqrt where the device has them) and once without them, so a device whose
default arithmetic is looser (NVIDIA's driver: 2.5-3 ulp division and sqrt) shows what the option buys.

Usage: TESSERA_OPENCL=require [TESSERA_OPENCL_DEVICE=name] python tools/opencl_agreement.py
Prints one JSON object per (build, path): differing values, values compared, the largest difference in ulps.
"""

import json

import numpy as np
from source_tree import as_package  # tools/ is first on sys.path


def ulp_distance(a, b):
    """(number of differing values, largest distance in ulps) between two float32 arrays of one shape."""
    ia, ib = (np.ascontiguousarray(x, np.float32).view(np.int32).astype(np.int64).ravel() for x in (a, b))
    ia, ib = (np.where(i < 0, -(i & 0x7FFFFFFF), i) for i in (ia, ib))  # ordered like the floats (-0 == +0)
    d = np.abs(ia - ib)
    return int(np.count_nonzero(d)), int(d.max()) if d.size else 0


def dab_rows():
    """Per dab kind: (differing, compared, max ulps) of OpenCL against numpy over the shared random dabs."""
    from tessera.kernels.displacement.map_edit import apply_dab
    from tessera.tools.generators import random_dabs

    rows = {}
    for channels in (1, 3, 4):
        rng = np.random.default_rng(channels)
        base = rng.normal(size=(64, 72, channels)).astype(np.float32)
        for kind, params in random_dabs(rng, channels):
            a, b = base.copy(), base.copy()
            apply_dab(a, kind, backend="opencl", **params)
            apply_dab(b, kind, backend="numpy", **params)
            n, m = ulp_distance(a, b)
            row = rows.setdefault(kind, [0, 0, 0])
            row[0], row[1], row[2] = row[0] + n, row[1] + a.size, max(row[2], m)
    return rows


def ham_row(runtime):
    """(differing, compared, max ulps) of the OpenCL HAM against numpy on the shared random height field."""
    from tessera.kernels.terrain import opencl_path as terrain_opencl
    from tessera.tools.generators import random_ham_case

    hm, ref = random_ham_case()
    got = terrain_opencl.ham(runtime, hm.heights(), 1.0 / 1.5)
    n, m = ulp_distance(got, ref)
    return [n, ref.size, m]


def main():
    as_package("tessera-agreement-")
    from tessera.kernels.common import opencl_runtime

    with_options = opencl_runtime.Runtime.base_options
    for build in ("without the build options", "with the build options"):
        if build.startswith("without"):
            opencl_runtime.Runtime.base_options = property(lambda self: ())
        opencl_runtime.configure(mode="require")
        runtime = opencl_runtime.get_runtime()
        rows = {**dab_rows(), "HAM": ham_row(runtime)}
        for path, (n, size, m) in rows.items():
            print(json.dumps({"device": runtime.description, "build": build, "options": list(runtime.base_options),
                              "path": path, "differing": n, "compared": size, "max_ulps": m}))
        opencl_runtime.Runtime.base_options = with_options


if __name__ == "__main__":
    main()

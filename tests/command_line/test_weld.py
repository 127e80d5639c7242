"""Exact welding (kernels tier): coincident float32 vertices merge, nothing else does."""

import numpy as np
from tessera.kernels.common.weld import weld_exact, weld_triangles


def test_coincident_vertices_merge_in_order_of_first_appearance():
    p = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
    keep, index = weld_exact(p)
    assert keep.tolist() == [0, 1, 4]
    assert index.tolist() == [0, 1, 0, 1, 2]
    assert np.array_equal(p[keep][index], p)


def test_negative_zero_is_zero_and_one_ulp_apart_is_not_the_same():
    one = np.float32(1.0)
    p = np.array([[0.0, 1, 2], [-0.0, 1, 2], [0.0, np.nextafter(one, np.float32(2)), 2]], np.float32)
    keep, index = weld_exact(p)
    assert index.tolist() == [0, 0, 1] and keep.tolist() == [0, 2]


def test_two_halves_of_a_grid_weld_into_the_whole_grid():
    rng = np.random.default_rng(1)
    n = 9
    y, x = np.mgrid[0:n, 0:n]
    z = rng.normal(size=(n, n)).astype(np.float32)
    pos = np.stack([x, y, z], -1).reshape(-1, 3).astype(np.float32)
    v = np.arange(n * n).reshape(n, n)
    quads = np.stack([v[:-1, :-1], v[:-1, 1:], v[1:, 1:], v[1:, :-1]], -1).reshape(-1, 4)
    tris = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    left = tris[(pos[tris][:, :, 0].max(1) <= 4)]
    right = tris[(pos[tris][:, :, 0].max(1) > 4)]

    def piece(t):  # a separate mesh: its own copy of the vertices it uses
        used, local = np.unique(t, return_inverse=True)
        return pos[used], local.reshape(-1, 3)

    (pa, ta), (pb, tb) = piece(left), piece(right)
    welded, wt, _, kept = weld_triangles(np.concatenate([pa, pb]), np.concatenate([ta, tb + len(pa)]))
    assert len(welded) == n * n and len(kept) == len(tris)
    as_points = {tuple(sorted(map(tuple, welded[t]))) for t in wt}
    assert as_points == {tuple(sorted(map(tuple, pos[t]))) for t in tris}


def test_a_triangle_collapsed_by_welding_is_dropped():
    p = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 0], [0, 1, 0]], np.float32)
    welded, tris, keep, kept = weld_triangles(p, np.array([[0, 1, 2], [0, 1, 3]]))
    assert kept.tolist() == [1] and tris.tolist() == [[0, 1, 2]] and len(welded) == 3


def test_the_farm_digest_tool_prints_the_same_digest_twice():
    """`tools/terrain_digest.py`, what a farm admin runs on each machine: digests of levels and meshes, stable."""
    import json
    import subprocess
    import sys
    from pathlib import Path

    tool = Path(__file__).resolve().parents[2] / "tools" / "terrain_digest.py"
    runs = [subprocess.run([sys.executable, str(tool), "--cameras", "3"], capture_output=True, text=True, timeout=300)
            for _ in range(2)]
    assert all(r.returncode == 0 for r in runs), runs[0].stderr[-2000:]
    a, b = (json.loads(r.stdout.strip().splitlines()[-1]) for r in runs)
    assert len(a["levels"]) == len(a["meshes"]) == 16 and (a["levels"], a["meshes"]) == (b["levels"], b["meshes"])

"""GPU refinement patterns and codes against the CPU refinement (kernel tier): same topology, same parameters."""

import numpy as np
import pytest
from tessera.kernels.common.mesh_arrays import MeshArrays
from tessera.kernels.common.topology import triangle_edges
from tessera.kernels.tessellation import patch_instances as pi
from tessera.kernels.tessellation.refine import refine
from tessera.kernels.tessellation.tessellate import SurfaceOptions, surface_inputs
from tessera.tools.generators import random_closed


def _mesh_and_levels(seed, spacing):
    positions, triangles = random_closed(seed)
    edges, _, _ = triangle_edges(triangles)
    rng = np.random.default_rng(seed)
    edge_levels = rng.uniform(1.0, 9.0, len(edges))
    inner = rng.uniform(1.0, 9.0, len(triangles))
    return positions, triangles, edge_levels, inner


@pytest.mark.parametrize("spacing", ["EQUAL", "FRACTIONAL_EVEN"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_patterns_rebuild_the_cpu_refinement(seed, spacing):
    """Stamping each class pattern with the codes' global numbering gives the CPU refinement's triangles, and
    the codes' parameters are the CPU refinement's."""
    positions, tris, edge_levels, inner = _mesh_and_levels(seed, spacing)
    ref = refine(tris, len(positions), edge_levels, inner, spacing)
    classes = pi.patch_classes(tris, len(positions), edge_levels, inner, spacing)
    owner, codes = pi.vertex_codes(ref, classes)
    _, face_edges, flipped = triangle_edges(tris)
    # global id of a pattern vertex of face f, from its code: the inverse of vertex_codes
    key_to_id = {(int(o), *(int(x) for x in c)): i for i, (o, c) in enumerate(zip(owner, codes, strict=True))}
    edge_start = ref.n_corners + np.cumsum(ref.edge_segments - 1) - (ref.edge_segments - 1)

    def global_id(f, code):
        kind, a, b, _ = (int(x) for x in code)
        if kind == pi.KIND_CORNER:
            return int(tris[f, a])
        if kind == pi.KIND_EDGE:
            n = int(classes.counts[f, a])
            jc = n - b if flipped[f, a] else b
            return int(edge_start[face_edges[f, a]] + jc - 1)
        return key_to_id[(f, *(int(x) for x in code))]

    got = []
    for key, faces in classes.classes.items():
        pcodes, ptris = pi.pattern(*key)
        for f in faces:
            ids = np.array([global_id(f, c) for c in pcodes])
            got.append(ids[ptris])
    got = np.concatenate(got)
    want = ref.triangles
    assert len(got) == len(want)
    rot = lambda t: np.array([np.roll(r, -int(np.argmin(r))) for r in t])  # noqa: E731
    assert np.array_equal(np.unique(rot(got), axis=0), np.unique(rot(want), axis=0))  # same oriented triangles
    # parameters: edge points at the CPU's t, interior points at its barycentrics, corners exact
    f = owner
    bary, edge_t = pi.code_parameters(codes, classes.levels[f], classes.counts[f], flipped[f], spacing)
    e0 = ref.n_corners
    e1 = e0 + len(ref.edge_point_edge)
    assert np.allclose(edge_t[e0:e1], ref.edge_point_t, atol=1e-12, rtol=0)
    assert np.allclose(bary[e1:], ref.interior_bary, atol=1e-12, rtol=0)
    corner_of = codes[: ref.n_corners, 1].astype(int)
    assert np.all(tris[f[: ref.n_corners], corner_of] == np.arange(ref.n_corners))


def test_rows_hold_the_shared_vertex_data_bit_for_bit():
    positions, tris, edge_levels, inner = _mesh_and_levels(3, "EQUAL")
    classes = pi.patch_classes(tris, len(positions), edge_levels, inner)
    mesh = MeshArrays(positions=positions, triangles=tris)
    inputs = surface_inputs(mesh, edge_levels, "PHONG", SurfaceOptions(alpha=0.5))
    rows = pi.control_rows(inputs, alpha=0.5)
    _, face_edges, flipped = triangle_edges(tris)
    assert rows.shape == (len(tris), pi.CONTROL_ROWS, 4)
    assert np.array_equal(rows[:, 3:6, 3] == 1, flipped)
    assert np.all(rows[:, :3, 3] == 0.5)
    for r in range(3):  # a vertex has the same position and geometry normal in every triangle that uses it
        assert np.array_equal(rows[:, r, :3], positions[tris[:, r]])
        assert np.array_equal(rows[:, 3 + r, :3], inputs.vertex_normals[tris[:, r]].astype(np.float32))
    # both triangles of an edge see the same clamped level and segment count for it
    instances = pi.instance_rows(classes, np.arange(len(tris)))
    for values in (instances[:, 0, :3], classes.counts[:, :3]):
        per_edge = np.full(face_edges.max() + 1, np.nan)
        per_edge[face_edges.ravel()] = values.ravel()  # the last writer wins
        assert np.array_equal(per_edge[face_edges], values)  # ... and every other writer agrees

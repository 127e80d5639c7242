"""Whole meshes: welding, crack-freedom, closedness, determinism, errors."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from mesh_checks import is_closed_oriented_manifold
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.common.topology import triangle_edges
from tessera.kernels.tessellation.interpolate import point_values
from tessera.kernels.tessellation.refine import refine, refinement_counts
from tessera.tools.generators import grid, octahedron, random_closed, torus

SPACINGS = ["EQUAL", "FRACTIONAL_EVEN"]


def random_levels(seed, n, high=12.0):
    return np.random.default_rng(seed).uniform(1.0, high, n)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000), st.sampled_from(SPACINGS))
def test_closed_manifold_in_closed_manifold_out(seed, spacing):
    v, f = random_closed(seed)
    edges, _, _ = triangle_edges(f)
    ref = refine(f, len(v), random_levels(seed, len(edges)), spacing=spacing)
    assert is_closed_oriented_manifold(ref.triangles)
    # Euler characteristic of a torus is 0, before and after.
    n_edges = 3 * len(ref.triangles) // 2
    assert ref.n_vertices - n_edges + len(ref.triangles) == 0
    assert refinement_counts(f, len(v), random_levels(seed, len(edges)), spacing=spacing) == (
        ref.n_vertices, len(ref.triangles))


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000), st.sampled_from(SPACINGS))
def test_shared_edges_are_bit_identical_from_both_sides(seed, spacing):
    """Refine every triangle on its own (as a GPU instance would) and compare the shared-edge points."""
    v, f = random_closed(seed)
    edges, face_edges, _ = triangle_edges(f)
    levels = random_levels(seed, len(edges))
    welded = refine(f, len(v), levels, spacing=spacing)
    welded_pos = point_values(welded, v, backend="numpy")
    per_edge = {}
    for t in range(len(f)):
        own_edges, own_face_edges, _ = triangle_edges(f[t : t + 1])
        # map the triangle's own (sorted) edges to the mesh's edge ids to fetch their levels
        lut = {tuple(e): i for i, e in enumerate(edges)}
        own_levels = np.array([levels[lut[tuple(e)]] for e in own_edges])
        single = refine(f[t : t + 1], len(v), own_levels, spacing=spacing)
        pos = point_values(single, v, backend="numpy")
        for k, e in enumerate(own_edges):
            pts = pos[single.n_corners : single.n_corners + len(single.edge_point_edge)][single.edge_point_edge == k]
            per_edge.setdefault(lut[tuple(e)], []).append(pts)
    for edge_id, sides in per_edge.items():
        assert len(sides) == 2
        assert np.array_equal(sides[0], sides[1]), f"edge {edge_id} differs between its two triangles"
        mine = welded_pos[welded.n_corners : welded.n_corners + len(welded.edge_point_edge)][
            welded.edge_point_edge == edge_id]
        assert np.array_equal(mine, sides[0])


@pytest.mark.parametrize("spacing", SPACINGS)
def test_output_is_welded(spacing):
    v, f = torus()
    edges, _, _ = triangle_edges(f)
    ref = refine(f, len(v), random_levels(3, len(edges)), spacing=spacing)
    pos = point_values(ref, v, backend="numpy")
    assert len(np.unique(pos, axis=0)) == len(pos)  # no duplicate vertices anywhere
    assert len(np.unique(ref.triangles)) == ref.n_vertices  # and none unused


def test_open_mesh_keeps_its_boundary():
    v, f = grid(3)
    edges, _, _ = triangle_edges(f)
    ref = refine(f, len(v), np.full(len(edges), 4.0))
    e_out, counts = np.unique(np.sort(np.stack([ref.triangles, np.roll(ref.triangles, -1, 1)], -1).reshape(-1, 2), 1),
                              axis=0, return_counts=True)
    assert set(counts) == {1, 2}
    assert np.sum(counts == 1) == 4 * 3 * 4  # 12 boundary edges, each split in 4


def test_uniform_mesh_counts():
    v, f = octahedron()
    edges, _, _ = triangle_edges(f)
    for n in (1, 2, 3, 8):
        ref = refine(f, len(v), np.full(len(edges), float(n)))
        assert len(ref.triangles) == len(f) * ((3 * n * n) // 2 if n > 1 else 1)
        assert np.all(np.bincount(ref.triangle_face) == len(ref.triangles) // len(f))


def test_inner_levels_may_differ_from_edges():
    v, f = octahedron()
    edges, _, _ = triangle_edges(f)
    ref = refine(f, len(v), np.ones(len(edges)), inner_levels=np.full(len(f), 5.0))
    assert len(ref.triangles) == 8 * 25  # [Khronos]: outer (1,1,1), inner 5 -> 25 triangles
    assert is_closed_oriented_manifold(ref.triangles)


def test_deterministic_bytes():
    v, f = random_closed(7)
    edges, _, _ = triangle_edges(f)
    levels = random_levels(7, len(edges))
    a, b = (refine(f, len(v), levels, spacing="FRACTIONAL_EVEN") for _ in range(2))
    for name in ("triangles", "triangle_face", "corner_bary", "edge_point_t", "interior_bary"):
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes()


@pytest.mark.parametrize(
    "tris, n_vertices, levels, match",
    [
        (np.zeros((0, 3), np.int32), 3, np.zeros(0), "no faces"),
        (np.array([[0, 1, 5]]), 3, np.ones(3), "must lie in"),
        (np.array([[0, 1, 1]]), 3, np.ones(2), "same vertex twice"),
        (np.array([[0, 1, 2]]), 3, np.ones(2), "one per edge"),
        (np.array([[0, 1, 2]]), 3, np.array([1.0, np.nan, 2.0]), "finite"),
        (np.array([[0.0, 1, 2]]), 3, np.ones(3), "integers"),
    ],
)
def test_bad_input_is_a_clear_error(tris, n_vertices, levels, match):
    with pytest.raises(InvalidInputError, match=match):
        refine(tris, n_vertices, levels)


@pytest.mark.parametrize("spacing", ["EQUAL", "FRACTIONAL_EVEN"])
@pytest.mark.parametrize("levels", ["uniform", "pow2", "random"])
def test_class_path_equals_general_path(spacing, levels, monkeypatch):
    from tessera.kernels.tessellation import refine_templates

    v, f = random_closed(7, 6, 5)
    edges, _, _ = triangle_edges(f)
    rng = np.random.default_rng(2)
    lv = {"uniform": np.full(len(edges), 5.5), "pow2": 2.0 ** rng.integers(0, 4, len(edges)),
          "random": rng.uniform(1, 9, len(edges))}[levels]
    monkeypatch.setattr(refine_templates, "worth_it", lambda classes, n: True)
    by_class = refine(f, len(v), lv, spacing=spacing)
    assert by_class.face_class is not None
    monkeypatch.setattr(refine_templates, "worth_it", lambda classes, n: False)
    general = refine(f, len(v), lv, spacing=spacing)
    assert general.face_class is None
    for name in ("triangles", "triangle_face", "edge_point_t", "interior_face", "interior_counts"):
        assert np.array_equal(getattr(by_class, name), getattr(general, name)), name
    np.testing.assert_allclose(by_class.interior_bary, general.interior_bary, rtol=0, atol=1e-15)
    np.testing.assert_allclose(by_class.corner_bary, general.corner_bary, rtol=0, atol=1e-15)


def _check_output_edges(ref):
    out_edges, corner_edges = ref.output_edges()
    tris = ref.triangles.astype(np.int64)
    nxt = np.roll(tris, -1, axis=1)
    got = np.sort(out_edges[corner_edges].astype(np.int64), axis=-1)  # (M, 3, 2)
    assert np.array_equal(got, np.sort(np.stack((tris, nxt), axis=-1), axis=-1))  # every corner's edge
    keys = np.sort(out_edges.astype(np.int64), axis=1) @ np.array([ref.n_vertices, 1])
    half = np.sort(np.stack((tris, nxt), axis=-1), axis=-1).reshape(-1, 2) @ np.array([ref.n_vertices, 1])
    assert len(np.unique(keys)) == len(keys) == len(np.unique(half))  # each edge once, none missing
    assert np.array_equal(np.bincount(corner_edges.ravel(), minlength=len(out_edges)) > 0,
                          np.ones(len(out_edges), bool))


@pytest.mark.parametrize("spacing", SPACINGS)
@pytest.mark.parametrize("levels", ["uniform", "pow2", "random"])
def test_output_edges_from_the_patterns(spacing, levels, monkeypatch):
    """Both paths name the output mesh's edges (so writers skip edge computation): every triangle
    corner's edge joins that corner and the next, each edge is listed once, none is missing; closed and open
    meshes."""
    from tessera.kernels.tessellation import refine_templates

    monkeypatch.setattr(refine_templates, "worth_it", lambda classes, n: True)
    rng = np.random.default_rng(5)
    for v, f in (random_closed(3, 6, 5), grid(4)):
        edges, _, _ = triangle_edges(f)
        lv = {"uniform": np.full(len(edges), 6.0), "pow2": 2.0 ** rng.integers(0, 4, len(edges)),
              "random": rng.uniform(1, 9, len(edges))}[levels]
        _check_output_edges(refine(f, len(v), lv, spacing=spacing))
    monkeypatch.setattr(refine_templates, "worth_it", lambda classes, n: False)
    for v, f in (random_closed(3, 6, 5), grid(4)):  # the per-face path (strips and interiors) names them too
        edges, _, _ = triangle_edges(f)
        lv = {"uniform": np.full(len(edges), 6.0), "pow2": 2.0 ** rng.integers(0, 4, len(edges)),
              "random": rng.uniform(1, 9, len(edges))}[levels]
        split = refine(f, len(v), lv, spacing=spacing)
        assert split.face_class is None and split.has_output_edges
        _check_output_edges(split)


@pytest.mark.parametrize("spacing", SPACINGS)
def test_general_corner_values_per_slot_equal_per_corner(spacing, monkeypatch):
    """The general path weighs a corner attribute once per ring vertex and gathers it to the corners: the same
    bytes as weighing every corner, for float32 and float64 attributes with seams (faces disagree at shared
    vertices), and signed zeros."""
    import dataclasses

    from tessera.kernels.tessellation import refine_templates
    from tessera.kernels.tessellation.interpolate import corner_values

    monkeypatch.setattr(refine_templates, "worth_it", lambda classes, n: False)
    v, f = random_closed(11, 6, 5)
    edges, _, _ = triangle_edges(f)
    rng = np.random.default_rng(9)
    ref = refine(f, len(v), rng.uniform(1, 14, len(edges)), spacing=spacing)
    assert ref.arrays.corner_slots is not None
    per_corner = dataclasses.replace(ref, arrays=dataclasses.replace(ref.arrays, corner_slots=None))
    slot_face, slot_bary, triangle_slots = ref.arrays.corner_slots.get()
    assert np.array_equal(slot_bary[triangle_slots], ref.corner_bary)
    assert np.array_equal(slot_face[triangle_slots[:, 0]], ref.triangle_face)
    signed_zeros = rng.choice(np.array([-0.0, 0.0, -0.0, -1.5], np.float32), (len(f), 3, 2))  # -0 sums are +0
    for values in (rng.uniform(-3, 3, (len(f), 3, 2)).astype(np.float32), rng.normal(size=(len(f), 3, 4)),
                   rng.normal(size=(len(f), 3)), signed_zeros):
        got, want = corner_values(ref, values, "numpy"), corner_values(per_corner, values, "numpy")
        assert got.dtype == want.dtype == np.float32 and got.shape == want.shape
        assert got.tobytes() == want.tobytes()  # bytes: array_equal takes -0.0 for +0.0


@pytest.mark.parametrize("spacing", SPACINGS)
@pytest.mark.parametrize("seed", range(6))
def test_split_construction_equals_the_general_construction(spacing, seed):
    """Strips in closed form and interiors stamped per inner level give `refine_general`'s refinement bit for bit:
    vertex numbering, triangle order, barycentrics; levels from 1 (unrefined faces) to 40, inner levels given or
    not, closed and open meshes; and its output edges are the mesh's edges."""
    from tessera.kernels.tessellation.refine_general import face_levels, refine_general
    from tessera.kernels.tessellation.refine_split import refine_split

    rng = np.random.default_rng(seed)
    v, f = random_closed(seed + 3, 6, 5) if seed % 2 == 0 else grid(5)
    edges, face_edges, flipped = triangle_edges(f)
    lv = rng.uniform(0.5, [40, 3, 12][seed % 3], len(edges))
    lv[rng.random(len(edges)) < 0.3] = 1.0
    inner = None if seed < 3 else rng.uniform(0.5, 9, len(f))
    levels = face_levels(face_edges, len(edges), lv, inner, spacing)
    general = refine_general(f, len(v), edges, face_edges, flipped, levels, spacing)
    split = refine_split(f, len(v), edges, face_edges, flipped, levels, spacing)
    for name in ("triangles", "triangle_face", "interior_face", "interior_bary", "corner_bary", "edge_point_t",
                 "interior_counts"):
        a, b = getattr(general, name), getattr(split, name)
        assert a.dtype == b.dtype and np.array_equal(a, b), name
    assert general.n_triangles == split.n_triangles
    _check_output_edges(split)

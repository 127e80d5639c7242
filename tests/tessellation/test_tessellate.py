"""Attribute interpolation and the whole-mesh pipeline (numpy reference)."""

import numpy as np
import pytest
from tessera.kernels.common.budget import check_budget
from tessera.kernels.common.errors import BudgetError, InvalidInputError, TesseraError
from tessera.kernels.common.mesh_arrays import MeshArrays
from tessera.kernels.common.tolerances import LINEAR_REPRODUCTION_ATOL
from tessera.kernels.common.topology import triangle_edges
from tessera.kernels.tessellation.interpolate import corner_values, face_values, point_values
from tessera.kernels.tessellation.refine import refine
from tessera.kernels.tessellation.tessellate import estimate, tessellate, uniform_levels
from tessera.tools.generators import random_closed, torus


def mesh_with_attributes(seed=0):
    v, f = random_closed(seed, 6, 5)
    rng = np.random.default_rng(seed)
    # A per-face affine UV map: discontinuous across every edge, like UV islands with seams everywhere.
    uv_maps = rng.normal(size=(len(f), 3, 2))
    uv_offsets = rng.normal(size=(len(f), 2))
    uv = np.einsum("tkd,tde->tke", v[f], uv_maps) + uv_offsets[:, None, :]
    colour_map, colour_offset = rng.normal(size=(3, 4)), rng.normal(size=4)  # affine in position, 4 channels
    colour = v @ colour_map + colour_offset
    mesh = MeshArrays(
        positions=v,
        triangles=f,
        corner_normals=np.tile(np.array([0.0, 0.0, 1.0], np.float32), (len(f), 3, 1)),
        point_attributes={"colour": colour.astype(np.float32)},
        corner_attributes={"uv": uv.astype(np.float32)},
        face_attributes={"material_index": (np.arange(len(f)) % 3).astype(np.int32)},
    )
    return mesh, uv_maps, uv_offsets, (colour_map, colour_offset)


@pytest.mark.parametrize("spacing", ["EQUAL", "FRACTIONAL_EVEN"])
def test_linear_attributes_are_reproduced_exactly(spacing):
    mesh, uv_maps, uv_offsets, (colour_map, colour_offset) = mesh_with_attributes()
    levels = np.random.default_rng(1).uniform(1, 9, len(uv_maps) * 3 // 2)
    result = tessellate(mesh, levels, spacing=spacing, backend="numpy")
    out, ref = result.mesh, result.refinement
    pos = out.positions.astype(np.float64)
    # point attribute: the same affine function of the (float32) output position
    expected_colour = pos @ colour_map + colour_offset
    assert np.allclose(out.point_attributes["colour"], expected_colour, atol=LINEAR_REPRODUCTION_ATOL * 10)
    # corner attribute: each output corner follows the affine map of its own source face
    corner_pos = pos[out.triangles]
    face = ref.triangle_face
    expected_uv = np.einsum("mkd,mde->mke", corner_pos, uv_maps[face]) + uv_offsets[face][:, None]
    scale = max(1.0, np.abs(expected_uv).max())
    assert np.allclose(out.corner_attributes["uv"], expected_uv, atol=LINEAR_REPRODUCTION_ATOL * 10 * scale)
    # face attribute: copied from the source face
    assert np.array_equal(out.face_attributes["material_index"], mesh.face_attributes["material_index"][face])


def test_linear_method_keeps_every_vertex_on_its_face():
    mesh, *_ = mesh_with_attributes(3)
    result = tessellate(mesh, uniform_levels(mesh, 5), backend="numpy")
    out, ref = result.mesh, result.refinement
    corners = mesh.positions[mesh.triangles].astype(np.float64)
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    face = ref.triangle_face
    offset = np.einsum("mkd,md->mk", out.positions[out.triangles] - corners[face][:, :1], normal[face])
    assert np.abs(offset).max() < 1e-6
    area_in = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1).sum()
    p = out.positions[out.triangles].astype(np.float64)
    area_out = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()
    assert abs(area_out / area_in - 1) < 1e-6


def test_corner_normals_stay_unit():
    mesh, *_ = mesh_with_attributes(4)
    rng = np.random.default_rng(2)
    n = rng.normal(size=(len(mesh.triangles), 3, 3))
    mesh.corner_normals = (n / np.linalg.norm(n, axis=2, keepdims=True)).astype(np.float32)
    out = tessellate(mesh, uniform_levels(mesh, 4), backend="numpy").mesh
    assert np.allclose(np.linalg.norm(out.corner_normals, axis=2), 1.0, atol=1e-6)


def test_estimate_matches_the_result():
    mesh, *_ = mesh_with_attributes(5)
    levels = uniform_levels(mesh, 6)
    est = estimate(mesh, levels)
    out = tessellate(mesh, levels, backend="numpy").mesh
    assert (est.vertices, est.triangles) == (len(out.positions), len(out.triangles))
    with pytest.raises(BudgetError, match="over the memory budget"):
        check_budget(est, est.bytes - 1)
    check_budget(est, est.bytes)  # at the budget: accepted
    check_budget(est, 0)  # 0: no limit


def test_shape_errors():
    v, f = torus(5, 4)
    ref = refine(f, len(v), np.ones(len(triangle_edges(f)[0])))
    with pytest.raises(Exception, match="rows"):
        point_values(ref, v[:-1])
    with pytest.raises(Exception, match="expected"):
        corner_values(ref, np.zeros((len(f), 2, 2)))
    with pytest.raises(Exception, match="rows"):
        face_values(ref, np.zeros(len(f) + 1))
    bad = MeshArrays(positions=np.full((len(v), 3), np.nan, np.float32), triangles=f)
    with pytest.raises(InvalidInputError, match="NaN"):
        tessellate(bad, np.ones(len(triangle_edges(f)[0])))
    with pytest.raises(InvalidInputError, match="method"):
        tessellate(MeshArrays(positions=v, triangles=f), np.ones(len(triangle_edges(f)[0])), method="CUBIC")


def test_corner_values_by_class_equal_the_gather(monkeypatch):
    from tessera.kernels.tessellation import refine_templates

    mesh, *_ = mesh_with_attributes(2)
    levels = np.full(len(triangle_edges(mesh.triangles)[0]), 4.0)
    levels[::3] = 2.0  # a few classes, faces of a class not consecutive
    monkeypatch.setattr(refine_templates, "worth_it", lambda classes, n: True)
    ref = refine(mesh.triangles, len(mesh.positions), levels)
    assert ref.face_class is not None and len(ref.classes) > 1
    by_class = corner_values(ref, mesh.corner_attributes["uv"], backend="numpy")
    flat = mesh.corner_attributes["uv"].reshape(-1, 2)
    source = ref.triangle_face.astype(np.int64)[:, None] * 3 + np.arange(3)
    from tessera.kernels.tessellation.interpolate import gather_weighted_numpy
    gathered = gather_weighted_numpy(flat, np.repeat(source, 3, axis=0), ref.corner_bary.reshape(-1, 3))
    np.testing.assert_allclose(by_class.reshape(-1, 2), gathered, rtol=1e-6, atol=1e-6)


def test_corner_values_on_the_general_path_equal_the_gather_bit_for_bit(monkeypatch):
    from tessera.kernels.tessellation import refine_templates
    from tessera.kernels.tessellation.interpolate import gather_weighted_numpy

    mesh, *_ = mesh_with_attributes(3)
    levels = np.random.default_rng(4).uniform(1, 9, len(triangle_edges(mesh.triangles)[0]))
    monkeypatch.setattr(refine_templates, "worth_it", lambda classes, n: False)
    ref = refine(mesh.triangles, len(mesh.positions), levels, spacing="FRACTIONAL_EVEN")
    assert ref.face_class is None
    uv = mesh.corner_attributes["uv"]
    source = ref.triangle_face.astype(np.int64)[:, None] * 3 + np.arange(3)
    gathered = gather_weighted_numpy(uv.reshape(-1, 2), np.repeat(source, 3, axis=0), ref.corner_bary.reshape(-1, 3))
    for backend in ("auto", "numpy"):
        assert corner_values(ref, uv, backend=backend).tobytes() == gathered.tobytes()
    with pytest.raises(TesseraError, match="backend"):
        corner_values(ref, uv, backend="cuda")


def one_value_per_vertex(triangles, corner):
    """True when every output vertex has bit-identical corner values in all the triangles that use it."""
    ids = triangles.ravel()
    words = np.ascontiguousarray(corner.reshape(len(ids), -1)).view(np.uint32)
    order = np.lexsort(words.T[::-1].tolist() + [ids])
    same_vertex = ids[order][1:] == ids[order][:-1]
    same_value = (words[order][1:] == words[order][:-1]).all(axis=1)
    return bool(same_value[same_vertex].all())


def continuous_uvs(seed):
    """A closed mesh and per-vertex UVs given per corner: values that agree across every edge (no seams)."""
    v, f = random_closed(seed, 7, 6)
    uv = np.random.default_rng(seed).random((len(v), 2)).astype(np.float32) * 9.3 - 4.1
    return v, f, uv


@pytest.mark.parametrize("spacing", ["EQUAL", "FRACTIONAL_EVEN"])
@pytest.mark.parametrize("levels_kind, by_class", [("uniform", True), ("power_of_two", True), ("random", False)])
def test_corner_values_agree_bit_for_bit_at_shared_vertices(monkeypatch, spacing, levels_kind, by_class):
    """Both faces of an edge interpolate its points from the same ends with the same weights (an exporter that
    splits vertices on differing UVs must not split a seamless mesh)."""
    from tessera.kernels.tessellation import refine_templates

    v, f, uv = continuous_uvs(4)
    n_edges = len(triangle_edges(f)[0])
    rng = np.random.default_rng(9)
    levels = {"uniform": np.full(n_edges, 7.0), "power_of_two": 2.0 ** rng.integers(0, 4, n_edges),
              "random": rng.uniform(1, 9, n_edges)}[levels_kind]
    monkeypatch.setattr(refine_templates, "worth_it", lambda classes, n: by_class)
    ref = refine(f, len(v), levels, spacing=spacing)
    assert (ref.face_class is not None) == by_class
    out = corner_values(ref, uv[f], backend="numpy")
    assert one_value_per_vertex(ref.triangles, out)
    corners = ref.triangles < len(v)  # input vertices keep their value exactly
    assert np.array_equal(out[corners], uv[ref.triangles[corners]])


@pytest.mark.parametrize("method", ["LINEAR", "PHONG", "PN"])
@pytest.mark.parametrize("spacing", ["EQUAL", "FRACTIONAL_EVEN"])
def test_per_face_levels_give_the_general_construction_bytes(method, spacing, monkeypatch):
    """Faces whose levels all differ take the per-face path (strips and stamped interiors); the whole tessellation
    (positions, triangles, normals, every attribute) has the same bytes as with the general construction it
    replaced, split corner normals included."""
    from tessera.kernels.tessellation import refine as refine_module
    from tessera.kernels.tessellation import refine_templates
    from tessera.kernels.tessellation.refine_general import refine_general

    mesh, uv_maps, _, _ = mesh_with_attributes(4)
    rng = np.random.default_rng(8)
    mesh.corner_normals = rng.normal(size=(len(mesh.triangles), 3, 3)).astype(np.float32)  # split everywhere
    levels = rng.uniform(1, 23, len(triangle_edges(mesh.triangles)[0]))
    monkeypatch.setattr(refine_templates, "worth_it", lambda classes, n: False)
    got = tessellate(mesh, levels, spacing=spacing, method=method, backend="numpy")
    assert got.refinement.face_class is None and got.refinement.arrays.corner_slots is not None
    monkeypatch.setattr(refine_module, "refine_split", refine_general)
    want = tessellate(mesh, levels, spacing=spacing, method=method, backend="numpy")
    assert not want.refinement.has_output_edges  # the general construction ran
    a, b = got.mesh, want.mesh
    for name in ("positions", "triangles", "point_normals", "corner_normals"):
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None) == (y is None), name
        assert x is None or (x.dtype == y.dtype and np.array_equal(x, y)), name
    for group in ("point_attributes", "corner_attributes", "face_attributes"):
        for key, x in getattr(a, group).items():
            y = getattr(b, group)[key]
            assert x.dtype == y.dtype and np.array_equal(x, y), key


@pytest.mark.parametrize("taps", [1, 2, 3])
def test_numpy_gather_is_the_tap_order_sum_bit_for_bit(taps):
    """`gather_weighted_numpy` works channel by channel; its bytes are those of ``sum(w * v)`` from a float64 +0 in
    tap order over whole rows: float32 and float64 values, signed zeros, rows split between blocks."""
    from tessera.kernels.tessellation.interpolate import GATHER_CHUNK, gather_weighted_numpy

    rng = np.random.default_rng(taps)
    n = GATHER_CHUNK + 777
    idx = rng.integers(0, 300, (n, taps))
    w = rng.dirichlet(np.ones(taps), n)
    w[:50] = np.eye(taps)[0]  # a corner: the other taps' products are signed zeros
    for values in (rng.normal(size=(300, 3)), rng.normal(size=(300, 2)).astype(np.float32),
                   rng.choice(np.array([-0.0, 0.0, -1.5]), (300, 4))):
        want = np.zeros((n, values.shape[1]))
        for t in range(taps):
            want += w[:, t, None] * values[idx[:, t]]
        got = gather_weighted_numpy(values, idx, w)
        assert got.dtype == np.float32 and got.tobytes() == want.astype(np.float32).tobytes()


@pytest.mark.parametrize("method, normal_mode", [("LINEAR", "WATERTIGHT"), ("PN", "WATERTIGHT"), ("PHONG", "SPLIT")])
def test_levels_carried_from_the_choice_to_the_refinement_build_the_edge_table_once(monkeypatch, method,
                                                                                    normal_mode):
    """The operator's walk: the edge table is built once (`mesh_topology`), the levels are chosen on it and clamped
    once (`mesh_levels`), and the estimate and the tessellation take that `MeshLevels` without building or clamping
    again (SPLIT builds the split mesh's own table, once). The mesh is byte for byte the one from plain arrays."""
    import tessera.kernels.common.topology as topology
    import tessera.kernels.tessellation.refine_general as refine_general
    from tessera.kernels.tessellation.mesh_levels import mesh_levels
    from tessera.kernels.tessellation.tessellate import SurfaceOptions

    mesh, _, _, _ = mesh_with_attributes(3)
    mesh.corner_normals = np.random.default_rng(4).normal(size=(len(mesh.triangles), 3, 3)).astype(np.float32)
    options = SurfaceOptions(normal_mode=normal_mode)
    table = topology.mesh_topology(mesh.triangles, len(mesh.positions))
    raw = np.random.default_rng(5).uniform(0.5, 70, len(table.edges))
    inner = np.random.default_rng(6).uniform(0.5, 70, len(mesh.triangles))
    levels = mesh_levels(table, uniform_levels(mesh, 3.0, table) + raw, inner, "FRACTIONAL_EVEN")
    calls = {"edges": 0, "clamps": 0}

    def counted(name, function):
        def call(*args, **kwargs):
            calls[name] += 1
            return function(*args, **kwargs)
        return call

    monkeypatch.setattr(topology, "triangle_edges", counted("edges", topology.triangle_edges))
    monkeypatch.setattr(refine_general, "clamp_levels", counted("clamps", refine_general.clamp_levels))
    estimated = estimate(mesh, levels)
    carried = tessellate(mesh, levels, method=method, options=options, backend="numpy")
    split = normal_mode == "SPLIT"
    assert calls == {"edges": int(split), "clamps": 2 * split}  # SPLIT: the split mesh's own table and levels, once
    monkeypatch.undo()
    plain = tessellate(mesh, uniform_levels(mesh, 3.0) + raw, inner, spacing="FRACTIONAL_EVEN", method=method,
                       options=options, backend="numpy")
    assert estimated.triangles == len(plain.mesh.triangles)
    assert estimated.vertices == len(plain.mesh.positions) or split  # SPLIT opens edges: their points twice
    assert carried.mesh.positions.tobytes() == plain.mesh.positions.tobytes()
    assert carried.mesh.triangles.tobytes() == plain.mesh.triangles.tobytes()
    with pytest.raises(InvalidInputError, match="These levels are for a mesh of"):
        tessellate(MeshArrays(positions=mesh.positions[:-1], triangles=mesh.triangles[:-1]), levels)

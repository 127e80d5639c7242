"""Loop subdivision kernel ([Concheiro et al.]): golden values, the cf table, counts and closure, OpenSubdiv's Loop
scheme and trimesh as oracles, creases, boundaries, face-varying data, 1-ring support."""

import numpy as np
import pytest
from loop_oracles import match_faces, match_vertices, opensubdiv, rel_err
from mesh_checks import is_closed_oriented_manifold
from tessera.kernels.common.errors import BudgetError, InvalidInputError
from tessera.kernels.subdivision.loop import estimate, loop_subdivide
from tessera.kernels.subdivision.loop_rules import correction_factor, correction_table, crease_to_sharpness, loop_beta
from tessera.kernels.subdivision.loop_topology import coarse_level
from tessera.tools.generators import (
    bipyramid,
    cup,
    grid,
    icosahedron,
    octahedron,
    plane_with_hole,
    random_irregular_closed,
    torus,
)

pytestmark = pytest.mark.usefixtures("numpy_reference")  # the numpy reference; OpenCL is compared elsewhere


# cf(n) and beta(n) for n = 3..12 as [Concheiro et al.] tabulates them, to the printed 6 decimals.
CF_TABLE = [1.5, 1.291667, 1.121243, 1.0, 0.915132, 0.854780, 0.810840, 0.778073, 0.753089, 0.733654]
BETA_TABLE = [0.1875, 0.121094, 0.084093, 0.0625, 0.049025, 0.040068, 0.033785, 0.029178, 0.025673, 0.022927]


def closed_meshes():
    yield "octahedron", octahedron()
    yield "icosahedron", icosahedron()
    yield "bipyramid16", bipyramid(16)
    yield "torus", torus(8, 5)
    for seed in range(3):
        yield f"irregular{seed}", random_irregular_closed(seed)


def open_meshes():
    yield "grid", grid(3)
    yield "plane_with_hole", plane_with_hole(6)
    yield "cup", cup()
    yield "triangle", (np.array([[0, 0, 0], [1, 0, 0], [0.2, 1, 0.3]], float), np.array([[0, 1, 2]]))
    strip_v = np.array([[i // 2, i % 2, 0.1 * i] for i in range(8)], float)
    strip_f = np.array([[i, i + 1, i + 2] if i % 2 == 0 else [i + 1, i, i + 2] for i in range(6)])
    yield "strip", (strip_v, strip_f)


def test_correction_factor_table_matches_the_factored_rule():
    assert np.allclose(correction_factor(np.arange(3, 13)), CF_TABLE, atol=5e-7)
    assert np.allclose(loop_beta(np.arange(3, 13)), BETA_TABLE, atol=5e-7)
    assert abs(correction_factor(6) - 1.0) <= np.spacing(1.0)
    n = np.arange(3, 40)
    # cf(n) * 3 / (8 n) is Loop's beta: the factored form is Loop's scheme.
    assert np.allclose(correction_factor(n) * 3 / (8 * n), loop_beta(n), rtol=1e-14)
    table = correction_table(20)
    assert len(table) == 21 and np.array_equal(table[3:], correction_factor(np.arange(3, 21)))


def test_golden_values_octahedron():
    v, f = octahedron()
    r1 = loop_subdivide(v, f, 1, dtype=np.float64)
    assert np.array_equal(r1.positions[0], [0.515625, 0, 0])
    odd = [i for i in range(6, len(r1.positions)) if np.allclose(r1.positions[i], [0.375, 0.375, 0], atol=1e-15)]
    assert len(odd) == 1
    r2 = loop_subdivide(v, f, 2, dtype=np.float64)
    norms = np.linalg.norm(r2.positions, axis=1)
    assert norms[0] == pytest.approx(0.447509765625, abs=1e-15)
    assert norms.min() == pytest.approx(0.435687, abs=5e-7) and norms.max() == pytest.approx(0.450258, abs=5e-7)
    assert (len(r1.positions), len(r1.triangles), len(r2.positions), len(r2.triangles)) == (18, 32, 66, 128)


def test_golden_values_icosahedron():
    v, f = icosahedron()
    r1 = loop_subdivide(v, f, 1, dtype=np.float64)
    norms = np.linalg.norm(r1.positions, axis=1)
    assert np.allclose(norms[:12], 0.767572059, atol=5e-10)
    assert np.allclose(norms[12:], 0.769420884, atol=5e-10)
    r2 = loop_subdivide(v, f, 2, dtype=np.float64)
    norms = np.linalg.norm(r2.positions, axis=1)
    assert norms[0] == pytest.approx(0.720032665, abs=5e-10)
    assert norms.min() == pytest.approx(0.716494, abs=5e-7) and norms.max() == pytest.approx(0.720519, abs=5e-7)
    assert (len(r1.positions), len(r2.positions), len(r2.triangles)) == (42, 162, 320)


@pytest.mark.parametrize("name, mesh", list(closed_meshes()), ids=lambda x: x if isinstance(x, str) else "")
def test_counts_closure_and_edges(name, mesh):
    v, f = mesh
    n_v, n_e, n_f = len(v), len(coarse_level(f, len(v)).edges), len(f)
    for level in range(1, 4):
        r = loop_subdivide(v, f, level)
        n_v, n_e, n_f = n_v + n_e, 2 * n_e + 3 * n_f, 4 * n_f
        assert (len(r.positions), len(r.edges), len(r.triangles)) == (n_v, n_e, n_f)
        assert n_v - n_e + n_f == len(v) - len(coarse_level(f, len(v)).edges) + len(f)  # Euler characteristic
        assert is_closed_oriented_manifold(r.triangles)
        # corner_edges name the edge between corners k and k + 1, and every edge is used
        k0 = np.sort(np.stack([r.triangles, np.roll(r.triangles, -1, axis=1)], -1), axis=-1)
        assert np.array_equal(np.sort(r.edges[r.corner_edges], axis=-1), k0)
        assert np.array_equal(np.unique(r.corner_edges), np.arange(len(r.edges)))
        assert r.positions.dtype == np.float32 and np.all(np.isfinite(r.positions))


def _compare_with_opensubdiv(v, f, level, creases=None, boundary="EDGE_ONLY", tol=1e-12):
    osd = opensubdiv()
    ours = loop_subdivide(v, f, level, creases=creases, boundary=boundary, dtype=np.float64)
    pairs, sharp = (None, None) if creases is None else creases
    ref = osd.loop_refine(v, f, level, creases=None if creases is None else (pairs, sharp), boundary=boundary)
    m = match_vertices(ours.positions, ref.values, tol=1e-7)
    assert rel_err(ours.positions, ref.values[m]) <= tol
    match_faces(m[ours.triangles], ref.triangles)
    return ours, ref, m


@pytest.mark.parametrize("name, mesh", list(closed_meshes()), ids=lambda x: x if isinstance(x, str) else "")
def test_closed_meshes_equal_opensubdiv(name, mesh):
    v, f = mesh
    for level in (1, 2, 3):
        _compare_with_opensubdiv(v, f, level)


@pytest.mark.parametrize("boundary", ["EDGE_ONLY", "EDGE_AND_CORNER"])
@pytest.mark.parametrize("name, mesh", list(open_meshes()), ids=lambda x: x if isinstance(x, str) else "")
def test_open_meshes_equal_opensubdiv(name, mesh, boundary):
    v, f = mesh
    for level in (1, 2, 3):
        ours, _, _ = _compare_with_opensubdiv(v, f, level, boundary=boundary)
        assert np.all(np.isfinite(ours.positions))


@pytest.mark.parametrize("seed", range(4))
def test_creases_equal_opensubdiv(seed):
    """Infinitely sharp and semi-sharp creases (OpenSubdiv's uniform rule, blends where a crease fades)."""
    rng = np.random.default_rng(seed)
    v, f = random_irregular_closed(seed) if seed % 2 == 0 else cup()
    edges = coarse_level(f, len(v)).edges
    pick = rng.choice(len(edges), size=len(edges) // 4, replace=False)
    sharp = rng.choice([10.0, 0.4, 1.0, 1.6, 2.5, 3.0], size=len(pick)).astype(np.float32)
    for level in (1, 2, 3):
        _compare_with_opensubdiv(v, f, level, creases=(edges[pick], sharp))


def test_full_crease_keeps_a_cube_edge_a_uniform_b_spline():
    """A crease of sharpness 10 (Blender crease 1.0) follows the curve rules: even 3/4, 1/8, 1/8; odd 1/2, 1/2."""
    v, f = bipyramid(6)
    ring = np.stack([np.arange(6), (np.arange(6) + 1) % 6], 1)
    r = loop_subdivide(v, f, 1, creases=(ring, crease_to_sharpness(np.ones(6))), dtype=np.float64)
    assert np.allclose(r.positions[0], 0.75 * v[0] + 0.125 * (v[1] + v[5]), atol=1e-15)
    lv = coarse_level(f, len(v))
    e = int(np.flatnonzero((lv.edges == [0, 1]).all(axis=1))[0])
    assert np.allclose(r.positions[len(v) + e], 0.5 * (v[0] + v[1]), atol=1e-15)


def test_vertex_sharpness_equals_opensubdiv_corners():
    """Vertex sharpness (Blender's vertex crease): corners, fading ones blended, alone and beside creases."""
    v, f = random_irregular_closed(7)
    corners = np.array([0, 3, 5, 8]), np.array([10.0, 0.5, 2.0, 1.3], np.float32)
    vs = np.zeros(len(v), np.float32)
    vs[corners[0]] = corners[1]
    edges = coarse_level(f, len(v)).edges
    creases = edges[::5], np.full(len(edges[::5]), 1.5, np.float32)
    osd = opensubdiv()
    for level in (1, 2, 3):
        for c in (None, creases):
            ours = loop_subdivide(v, f, level, creases=c, vertex_sharpness=vs, dtype=np.float64)
            ref = osd.loop_refine(v, f, level, creases=c, corners=corners)
            m = match_vertices(ours.positions, ref.values, tol=1e-7)
            assert rel_err(ours.positions, ref.values[m]) <= 1e-12
    assert np.array_equal(ours.positions[0], v[0])  # an infinitely sharp corner does not move


def test_trimesh_subdivide_loop_agrees():
    """trimesh's ``subdivide_loop``, a second pure-numpy Loop: closed meshes and the cup's boundary. (It returns
    NaN on meshes with boundary vertices of a single face, such as the plane with a hole, so those are left out.)"""
    from trimesh.remesh import subdivide_loop

    for _, (v, f) in [*closed_meshes(), ("cup", cup())]:
        tv, tf = subdivide_loop(np.asarray(v, np.float64), np.asarray(f, np.int64), iterations=2)
        ours = loop_subdivide(v, f, 2, dtype=np.float64)
        m = match_vertices(ours.positions, tv, tol=1e-7)
        assert rel_err(ours.positions, tv[m]) <= 1e-12
        match_faces(m[ours.triangles], tf)


def test_face_varying_uvs_equal_opensubdiv_linear_boundaries():
    """A torus with a UV seam around both wraps: corner UVs on their own mesh, seams and borders linear."""
    osd = opensubdiv()
    major, minor = 8, 5
    v, f = torus(major, minor)
    ij = np.stack(np.divmod(f, minor), -1).astype(float)  # (F, 3, 2) grid coordinates of each corner
    for axis, n in ((0, major), (1, minor)):
        lo = ij[:, :, axis].min(axis=1, keepdims=True)
        wrap = (ij[:, :, axis] - lo) > 1
        ij[:, :, axis] = np.where(wrap, ij[:, :, axis] - n, ij[:, :, axis])  # unwrap across the seam
    uv = ij / [major, minor] + 0.25 * np.sin(ij[..., ::-1])  # a non-linear map, so smoothing shows
    values, inverse = np.unique(uv.reshape(-1, 2), axis=0, return_inverse=True)
    for level in (1, 2):
        ours = loop_subdivide(v, f, level, corner_data={"UVMap": uv}, dtype=np.float64)
        ref = osd.loop_refine(v, f, level, fvar=(values, inverse.reshape(-1, 3)), fvar_interp="BOUNDARIES")
        m = match_vertices(ours.positions, ref.values, tol=1e-7)
        faces = match_faces(m[ours.triangles], ref.triangles)
        theirs = ref.fvar_values[ref.fvar_triangles[faces]]  # (F, 3, 2) in their corner order
        # align corners by vertex id
        their_tris = ref.triangles[faces]
        ours_ids = m[ours.triangles]
        order = np.argmax(their_tris[:, None, :] == ours_ids[:, :, None], axis=2)
        aligned = np.take_along_axis(theirs, order[..., None], axis=1)
        assert rel_err(ours.corner_attributes["UVMap"], aligned) <= 1e-12
        # seams stay linear: corner UVs on a coarse seam edge lie on the straight segment
        assert np.all(np.isfinite(ours.corner_attributes["UVMap"]))


def test_point_data_is_subdivided_like_positions():
    v, f = random_irregular_closed(3)
    weights = np.linspace(0, 1, len(v))
    colour = np.stack([weights, 1 - weights, weights**2, np.ones(len(v))], 1)
    r = loop_subdivide(v, f, 2, point_data={"w": weights, "Col": colour, "copy": v}, dtype=np.float64)
    assert r.point_attributes["w"].shape == (len(r.positions),)
    assert r.point_attributes["Col"].shape == (len(r.positions), 4)
    assert np.array_equal(r.point_attributes["copy"], r.positions)
    assert np.allclose(r.point_attributes["Col"][:, 3], 1.0, atol=1e-14)  # affine weights


def test_one_ring_support():
    """Perturbing every vertex outside a coarse triangle's 1-ring leaves its sub-triangles unchanged, bit for bit."""
    v, f = random_irregular_closed(11)
    rng = np.random.default_rng(0)
    for t in rng.choice(len(f), 4, replace=False):
        ring = np.unique(f[np.isin(f, f[t]).any(axis=1)])
        moved = v.copy()
        outside = np.setdiff1d(np.arange(len(v)), ring)
        moved[outside] += rng.normal(size=(len(outside), 3))
        for level in (1, 2, 3):
            a = loop_subdivide(v, f, level, dtype=np.float64)
            b = loop_subdivide(moved, f, level, dtype=np.float64)
            mine = a.coarse_face() == t
            assert np.array_equal(a.positions[a.triangles[mine]], b.positions[b.triangles[mine]])
            assert not np.array_equal(a.positions, b.positions)


def test_order_of_faces_and_vertices_does_not_change_the_surface():
    v, f = random_irregular_closed(5)
    rng = np.random.default_rng(1)
    perm_f = rng.permutation(len(f))
    perm_v = rng.permutation(len(v))
    inv_v = np.argsort(perm_v)
    a = loop_subdivide(v, f, 3, dtype=np.float64)
    b = loop_subdivide(v[perm_v], inv_v[f[perm_f]], 3, dtype=np.float64)
    m = match_vertices(a.positions, b.positions, tol=1e-7)
    assert rel_err(a.positions, b.positions[m]) <= 1e-14
    match_faces(m[a.triangles], b.triangles)
    # faces keep their coarse triangle: face j of b comes from b's coarse face perm_f[...]
    faces = match_faces(m[a.triangles], b.triangles)
    assert np.array_equal(perm_f[b.coarse_face()[faces]], a.coarse_face())


def test_output_edges_know_their_coarse_edge():
    v, f = random_irregular_closed(6)
    lv = coarse_level(f, len(v))
    r = loop_subdivide(v, f, 3, dtype=np.float64)
    coarse = r.coarse_edge()
    on = coarse >= 0
    assert on.sum() == 8 * len(lv.edges)
    # the 8 output edges on each coarse edge are a path from one of its ends to the other
    for e in range(0, len(lv.edges), 7):
        ids, counts = np.unique(r.edges[coarse == e], return_counts=True)
        ends = set(ids[counts == 1])
        assert ends == set(lv.edges[e]) and np.all(counts[counts != 1] == 2) and len(ids) == 9
    values = r.edge_values(lv.edges[[3, 7]][:, ::-1], np.array([2.0, 5.0]))
    assert np.array_equal(np.flatnonzero(values == 2.0), np.flatnonzero(coarse == 3))
    assert np.array_equal(np.flatnonzero(values == 5.0), np.flatnonzero(coarse == 7))
    assert np.count_nonzero(values) == 16


def test_faces_follow_the_t_l_c_r_convention():
    v, f = octahedron()
    r = loop_subdivide(v, f, 1, dtype=np.float64)
    lv = coarse_level(f, len(v))
    for t in range(len(f)):
        a, b, c = f[t]
        m0, m1, m2 = len(v) + lv.face_edges[t]
        expect = [[a, m0, m2], [m0, b, m1], [m0, m1, m2], [m2, m1, c]]
        assert np.array_equal(r.triangles[4 * t : 4 * t + 4], expect)


def test_bad_input_is_refused():
    v, f = octahedron()
    with pytest.raises(InvalidInputError, match="non-manifold"):
        loop_subdivide(np.concatenate([v, [[0, 0, 2]]]), np.concatenate([f, [[0, 2, 6]]]), 1)
    with pytest.raises(InvalidInputError, match="levels"):
        loop_subdivide(v, f, 7)
    with pytest.raises(InvalidInputError, match="NaN"):
        loop_subdivide(np.where(np.arange(18).reshape(6, 3) == 4, np.nan, v), f, 1)
    with pytest.raises(InvalidInputError, match="boundary"):
        loop_subdivide(v, f, 1, boundary="SMOOTH")
    with pytest.raises(BudgetError, match="budget"):
        loop_subdivide(v, f, 6, budget_bytes=1000)
    est = estimate(6, 12, 8, 6)
    assert est.triangles == 8 * 4**6


def test_loose_vertices_stay_and_level_zero_is_a_copy():
    v, f = octahedron()
    v = np.concatenate([v, [[5.0, 5.0, 5.0]]])
    r = loop_subdivide(v, f, 2)
    assert np.array_equal(r.positions[6], v[6].astype(np.float32))
    r0 = loop_subdivide(v, f, 0)
    assert np.array_equal(r0.positions, v.astype(np.float32)) and np.array_equal(r0.triangles, f)

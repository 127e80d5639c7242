"""Tube kernels: frames, refinement, selection, rings, caps, LOD and the anti-aliasing clamp ([Nunes 2011, ch. 4])."""

import numpy as np
import pytest
from tessera.kernels.common.camera import Camera
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.tubes.builder import TubeSettings, build_tubes, pixel_world_size, prepare_lines
from tessera.kernels.tubes.curve_refine import catmull_rom, select_points
from tessera.kernels.tubes.frames import rotation_minimizing_frames, tangents
from tessera.kernels.tubes.polylines import Polylines, drop_duplicates, segment_lengths

pytestmark = pytest.mark.usefixtures("numpy_reference")  # the numpy reference; OpenCL is compared elsewhere


def helix(a=1.0, b=0.3, turns=2.0, n=400):
    s = np.linspace(0, 2 * np.pi * turns, n)
    return s, np.stack((a * np.cos(s), a * np.sin(s), b * s), axis=1)


def trefoil(n=300):
    s = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.stack((np.sin(s) + 2 * np.sin(2 * s), np.cos(s) - 2 * np.cos(2 * s), -np.sin(3 * s)), axis=1)


def edge_use(mesh):
    return np.bincount(mesh.corner_edges, minlength=len(mesh.edges))


def directed_edges(mesh):
    off = mesh.face_offsets
    nxt = np.arange(len(mesh.corner_verts)) + 1
    nxt[off[1:] - 1] = off[:-1]
    return np.stack((mesh.corner_verts, mesh.corner_verts[nxt]), axis=1)


def signed_volume(mesh):
    """Volume enclosed by a closed polygon mesh (fan triangulation of each face from its first corner)."""
    off = mesh.face_offsets
    p = mesh.positions.astype(np.float64)
    vol = 0.0
    for k in np.unique(mesh.face_sizes):
        faces = np.nonzero(mesh.face_sizes == k)[0]
        idx = mesh.corner_verts[off[faces][:, None] + np.arange(k)]
        for i in range(1, k - 1):
            a, b, c = p[idx[:, 0]], p[idx[:, i]], p[idx[:, i + 1]]
            vol += np.sum(np.einsum("ij,ij->i", a, np.cross(b, c))) / 6.0
    return vol


# ---- frames ----------------------------------------------------------------------------------------------------


def test_frames_are_orthonormal_and_right_handed():
    rng = np.random.default_rng(1)
    pts = np.cumsum(rng.normal(size=(500, 3)), axis=0)
    lines = Polylines.build(pts, [0, 200, 500], radius=0.1, cyclic=[False, True])
    t, n, b = rotation_minimizing_frames(lines)
    for v in (t, n, b):
        assert np.allclose(np.linalg.norm(v, axis=1), 1, atol=1e-12)
    assert np.abs(np.sum(t * n, axis=1)).max() < 1e-12
    assert np.abs(np.sum(t * b, axis=1)).max() < 1e-12
    assert np.allclose(np.cross(t, n), b, atol=1e-12)


@pytest.mark.parametrize("exact_tangents, tol", [(True, 1e-6), (False, 2e-3)])
def test_helix_frame_matches_the_analytic_rotation_minimising_frame(exact_tangents, tol):
    """On a helix the RMF turns against the Frenet frame at the rate -τ per unit arc length."""
    a, b = 1.0, 0.3
    s, pts = helix(a, b, turns=2, n=400)
    lines = Polylines.build(pts, [0, len(pts)])
    c = np.hypot(a, b)
    t_exact = np.stack((-a * np.sin(s), a * np.cos(s), np.full_like(s, b)), axis=1) / c
    t, r, _ = rotation_minimizing_frames(lines, t_exact if exact_tangents else None)
    n_frenet = np.stack((-np.cos(s), -np.sin(s), np.zeros_like(s)), axis=1)
    b_frenet = np.cross(t_exact, n_frenet)
    angle = np.unwrap(np.arctan2(np.sum(r * b_frenet, axis=1), np.sum(r * n_frenet, axis=1)))
    tau = b / c**2
    expected = angle[0] - tau * c * s
    assert np.abs(angle - expected).max() < tol


def test_closed_loop_has_no_seam_twist():
    pts = trefoil()
    lines = Polylines.build(pts, [0, len(pts)], cyclic=True)
    t, r, _ = rotation_minimizing_frames(lines)
    # twist between consecutive frames, measured after parallel transport, is spread evenly: same rate
    # per unit length on every segment including the closing one
    from tessera.kernels.tubes.frames import rotate, step_rotations

    nxt = np.roll(np.arange(len(pts)), -1)
    steps = step_rotations(np.stack((pts, pts[nxt]), axis=1), t, t[nxt])
    carried = rotate(steps, r)
    twist = np.arctan2(np.sum(np.cross(carried, r[nxt]) * t[nxt], axis=1), np.sum(carried * r[nxt], axis=1))
    rate = twist / np.linalg.norm(pts[nxt] - pts, axis=1)
    assert np.abs(rate - rate.mean()).max() < 1e-9
    assert np.abs(twist[-1]) < 0.05  # the seam step turns no more than any other step


def test_straight_lines_duplicates_and_reversals_give_no_nan():
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0], [2, 0, 0], [2, 0, 0], [2, 1e-20, 0],
                    [5, 5, 5], [5, 5, 5], [5, 5, 5]], float)
    lines = Polylines.build(pts, [0, 8, 11], radius=0.2)
    mesh = build_tubes(lines, TubeSettings(caps="ROUND"))
    assert np.all(np.isfinite(mesh.positions)) and np.all(np.isfinite(mesh.point_normals))
    assert any("fewer than two distinct points" in note for note in mesh.notes)
    clean = drop_duplicates(lines)
    assert clean.n_curves == 1 and clean.counts[0] == 5
    t = tangents(clean)
    assert np.all(np.isfinite(t)) and np.allclose(np.linalg.norm(t, axis=1), 1)


def test_bad_input_is_refused_with_a_clear_error():
    with pytest.raises(InvalidInputError, match="NaN"):
        Polylines.build([[0, 0, 0], [np.nan, 0, 0]], [0, 2])
    with pytest.raises(InvalidInputError, match="radii"):
        Polylines.build([[0, 0, 0], [1, 0, 0]], [0, 2], radius=-1.0)
    with pytest.raises(InvalidInputError, match="offsets"):
        Polylines.build([[0, 0, 0], [1, 0, 0]], [0, 3])
    lines = Polylines.build([[0, 0, 0], [1, 0, 0]], [0, 2])
    with pytest.raises(InvalidInputError, match="camera"):
        build_tubes(lines, TubeSettings(aa_clamp=True))


# ---- rings ------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("sides", [3, 8, 17])
def test_ring_vertices_lie_at_the_radius_perpendicular_to_the_tangent(sides):
    rng = np.random.default_rng(sides)
    pts = np.cumsum(rng.normal(size=(120, 3)), axis=0)
    radius = rng.uniform(0.05, 0.4, size=120)
    lines = Polylines.build(pts, [0, 50, 120], radius=radius, tilt=rng.uniform(-3, 3, 120), cyclic=[False, True])
    mesh = build_tubes(lines, TubeSettings(sides=sides))
    centre = np.repeat(pts, sides, axis=0)
    offset = mesh.positions - centre
    atol = 4 * np.finfo(np.float32).eps * np.abs(pts).max()  # positions are stored as float32
    assert np.allclose(np.linalg.norm(offset, axis=1), np.repeat(radius, sides), rtol=1e-6, atol=atol)
    t = np.repeat(tangents(lines), sides, axis=0)
    assert np.abs(np.sum(offset * t, axis=1)).max() < atol
    assert np.allclose(np.linalg.norm(mesh.point_normals, axis=1), 1, atol=1e-6)
    assert np.allclose(mesh.point_normals * np.repeat(radius, sides)[:, None], offset, atol=atol)


def test_faces_point_outward():
    lines = Polylines.build([[0, 0, 0], [0, 0, 1], [0, 0, 2]], [0, 3], radius=0.5)
    mesh = build_tubes(lines, TubeSettings(sides=16, caps="FLAT"))
    vol = signed_volume(mesh)
    ideal = np.pi * 0.25 * 2 * (16 / (2 * np.pi)) * np.sin(2 * np.pi / 16)  # area of the 16-gon times length
    assert vol == pytest.approx(ideal, rel=1e-5)


@pytest.mark.parametrize("caps", ["FLAT", "ROUND"])
@pytest.mark.parametrize("sides", [3, 4, 9, 16])
def test_capped_tubes_and_closed_tubes_are_watertight_and_manifold(caps, sides):
    rng = np.random.default_rng(7)
    pts = np.concatenate((np.cumsum(rng.normal(size=(40, 3)), axis=0), trefoil(60)))
    lines = Polylines.build(pts, [0, 25, 40, 100], radius=0.3, cyclic=[False, False, True])
    mesh = build_tubes(lines, TubeSettings(sides=sides, caps=caps))
    assert np.all(edge_use(mesh) == 2)  # every edge has exactly two faces: closed and manifold
    d = directed_edges(mesh)
    assert len(np.unique(d, axis=0)) == len(d)  # consistent orientation: each directed edge once
    e = mesh.edges[mesh.corner_edges]
    assert np.all(np.sort(e, axis=1) == np.sort(d, axis=1))  # corner edges match the corners
    assert len(np.unique(np.sort(mesh.edges, axis=1), axis=0)) == len(mesh.edges)
    if caps == "ROUND":
        assert signed_volume(mesh) > 0


def test_round_cap_vertices_lie_on_the_end_sphere():
    lines = Polylines.build([[0, 0, 0], [0, 0, 3]], [0, 2], radius=0.5)
    mesh = build_tubes(lines, TubeSettings(sides=12, caps="ROUND"))
    p = mesh.positions.astype(np.float64)
    beyond = (p[:, 2] < -1e-6) | (p[:, 2] > 3 + 1e-6)
    ends = np.where(p[beyond, 2:3] < 0, 0.0, 3.0)
    centre = np.concatenate((np.zeros((beyond.sum(), 2)), ends), axis=1)
    assert beyond.sum() > 12
    assert np.allclose(np.linalg.norm(p[beyond] - centre, axis=1), 0.5, rtol=1e-6)


def test_uvs_run_along_and_around():
    lines = Polylines.build([[0, 0, 0], [1, 0, 0], [3, 0, 0]], [0, 3], radius=0.1)
    mesh = build_tubes(lines, TubeSettings(sides=4))
    uv = mesh.corner_uvs
    assert uv.shape == (len(mesh.corner_verts), 2)
    x = mesh.positions[mesh.corner_verts, 0]
    assert np.allclose(uv[:, 0], x / 3.0, atol=1e-6)  # u is arc length / total length
    assert set(np.round(np.unique(uv[:, 1]), 6)) == {0.0, 0.25, 0.5, 0.75, 1.0}  # the seam has v = 0 and 1


def test_material_index_follows_the_curve():
    lines = Polylines.build([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], [0, 2, 4], material_index=[2, 5])
    mesh = build_tubes(lines, TubeSettings(sides=5, caps="FLAT"))
    assert sorted(np.unique(mesh.face_material)) == [2, 5]
    assert np.sum(mesh.face_material == 5) == 5 + 2


# ---- refinement and selection ----------------------------------------------------------------------------------


@pytest.mark.parametrize("kind", ["UNIFORM", "CENTRIPETAL"])
def test_catmull_rom_passes_through_the_points(kind):
    rng = np.random.default_rng(3)
    pts = rng.normal(size=(12, 3))
    lines = Polylines.build(pts, [0, 5, 12], radius=np.linspace(1, 2, 12), cyclic=[False, True])
    out = catmull_rom(lines, 6, kind)
    assert list(out.counts) == [4 * 6 + 1, 7 * 6]
    assert np.allclose(out.points[out.offsets[0]:out.offsets[1]][::6], pts[:5])
    assert np.allclose(out.points[out.offsets[1]:][::6], pts[5:])
    assert np.allclose(out.radius[::6][:5], np.linspace(1, 2, 12)[:5])
    # a smooth curve: consecutive samples are close compared with the input spacing
    steps = np.linalg.norm(np.diff(out.points[:25], axis=0), axis=1)
    assert steps.max() < np.linalg.norm(np.diff(pts[:5], axis=0), axis=1).max()


def test_catmull_rom_reproduces_a_straight_evenly_spaced_line():
    pts = np.stack((np.arange(5.0), np.zeros(5), np.zeros(5)), axis=1)
    out = catmull_rom(Polylines.build(pts, [0, 5]), 4, "CENTRIPETAL")
    assert np.allclose(out.points[:, 0], np.arange(17) / 4) and np.allclose(out.points[:, 1:], 0)


def test_point_selection_drops_straight_runs_and_keeps_corners():
    run = np.stack((np.linspace(0, 10, 101), np.zeros(101), np.zeros(101)), axis=1)
    up = np.stack((np.full(100, 10.0), np.linspace(0.1, 10, 100), np.zeros(100)), axis=1)
    lines = Polylines.build(np.concatenate((run, up)), [0, 201], radius=0.1)
    out = select_points(lines, np.radians(5))
    assert np.allclose(out.points, [[0, 0, 0], [10, 0, 0], [10, 10, 0]])
    # a circle keeps a point every time the tangent turns by another 10 degrees
    s = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    circle = Polylines.build(np.stack((np.cos(s), np.sin(s), 0 * s), axis=1), [0, 720], cyclic=True)
    kept = select_points(circle, np.radians(10)).counts[0]
    assert 34 <= kept <= 37


def test_prepare_keeps_the_ends_of_open_curves():
    rng = np.random.default_rng(11)
    pts = np.cumsum(rng.normal(size=(30, 3)), axis=0)
    lines = Polylines.build(pts, [0, 30])
    out = prepare_lines(lines, TubeSettings(refine=4, select_angle=np.radians(20)))
    assert np.allclose(out.points[0], pts[0]) and np.allclose(out.points[-1], pts[-1])
    assert 2 <= out.counts[0] < 29 * 4 + 1


# ---- camera: LOD and anti-aliasing ------------------------------------------------------------------------------


def test_pixel_world_size_matches_the_pinhole_formula():
    cam = Camera.looking_at((0, -10, 0), (0, 0, 0), fov_deg=40, width=800, height=600)
    pts = np.array([[0, 0, 0], [0, 40, 0], [3, 90, 1]], float)
    depth = pts[:, 1] + 10
    expected = 2 * depth * np.tan(np.radians(20)) * (800 / 600) / 800
    assert np.allclose(pixel_world_size(pts, cam), expected, rtol=1e-6)
    assert np.isinf(pixel_world_size(np.array([[0, -20.0, 0]]), cam)[0])


def _projected_widths(mesh, cam, sides, rings):
    vp = cam.projection @ cam.view
    p = mesh.positions.astype(np.float64)
    clip = p @ vp[:3, :3].T + vp[:3, 3]
    w = p @ vp[3, :3] + vp[3, 3]
    px = (clip[:, :2] / w[:, None] * 0.5 + 0.5) * (cam.width, cam.height)
    return np.ptp(px.reshape(rings, sides, 2)[..., 1], axis=1)  # tube along screen x: width in screen y


@pytest.mark.parametrize("sides", [3, 6, 8])
def test_a_far_tube_keeps_two_pixels_with_the_clamp(sides):
    cam = Camera.looking_at((0, 0, 0), (0, 1, 0), fov_deg=50, width=640, height=480, far=1e6)
    for distance in (50.0, 500.0, 5000.0):
        x = np.linspace(-0.2, 0.2, 9) * distance
        pts = np.stack((x, np.full(9, distance), np.zeros(9)), axis=1)
        lines = Polylines.build(pts, [0, 9], radius=1e-4, tilt=0.37)
        clamped = build_tubes(lines, TubeSettings(sides=sides, aa_clamp=True), camera=cam)
        widths = _projected_widths(clamped, cam, sides, 9)
        assert widths.min() >= 2.0 - 1e-3
        plain = build_tubes(lines, TubeSettings(sides=sides))
        assert _projected_widths(plain, cam, sides, 9).max() < 0.5  # without the clamp it would vanish


def test_max_radius_caps_the_inflation_but_never_shrinks():
    cam = Camera.looking_at((0, 0, 0), (0, 1, 0), width=100, height=100, far=1e6)
    pts = np.array([[0, 1000, 0], [1, 1000, 0]], float)
    lines = Polylines.build(pts, [0, 2], radius=[1e-3, 5.0])
    mesh = build_tubes(lines, TubeSettings(sides=8, aa_clamp=True, max_radius=0.5), camera=cam)
    r = np.linalg.norm(mesh.positions.reshape(2, 8, 3) - pts[:, None], axis=2)
    assert np.allclose(r[0], 0.5, atol=1e-4) and np.allclose(r[1], 5.0, atol=1e-4)  # float32 at y = 1000


def test_camera_sides_never_increase_with_distance():
    cam = Camera.looking_at((0, 0, 0), (0, 1, 0), fov_deg=40, width=1000, height=1000, far=1e6)
    d = np.geomspace(2, 2000, 30)
    pts = np.stack((np.zeros((30, 2)), np.zeros((30, 2)) + d[:, None], np.array([[0, 0.5]] * 30)), axis=-1)
    lines = Polylines.build(pts.reshape(-1, 3), np.arange(0, 61, 2), radius=0.3)
    from tessera.kernels.tubes.builder import tube_sides

    settings = TubeSettings(sides_mode="CAMERA", min_sides=3, max_sides=32, edge_pixels=6)
    sides = tube_sides(lines, settings, pixel_world_size(lines.points, cam))
    assert np.all(np.diff(sides) <= 0) and sides[0] == 32 and sides[-1] == 3
    mesh = build_tubes(lines, settings, camera=cam)
    assert len(mesh.positions) == 2 * sides.sum()


def test_segment_tables_in_closed_form():
    """The OpenCL body's per-point tables (the segment starting at each point, its second point), written in order,
    are the scatter through the run's segments: open and cyclic curves, runs of some of the curves."""
    from tessera.kernels.tubes.builder import _run_topology
    from tessera.kernels.tubes.opencl_path import segment_tables
    from tessera.kernels.tubes.polylines import Polylines

    rng = np.random.default_rng(3)
    for _ in range(50):
        k = int(rng.integers(1, 12))
        counts = rng.integers(2, 7, k)
        lines = Polylines.build(rng.normal(size=(counts.sum(), 3)), np.concatenate(([0], np.cumsum(counts))),
                                radius=0.1, cyclic=rng.random(k) < 0.4)
        run = _run_topology(lines, np.sort(rng.permutation(k)[: int(rng.integers(1, k + 1))]))
        seg_of = np.full(run.n_pts, -1, np.int32)
        seg_of[run.seg] = np.arange(len(run.seg))
        nxt = np.zeros(run.n_pts, np.int32)
        nxt[run.seg] = run.nxt
        got = segment_tables(run)
        assert got[0].dtype == got[1].dtype == np.int32
        assert np.array_equal(got[0], seg_of) and np.array_equal(got[1], nxt)


@pytest.mark.parametrize("n_points", [5, 3 * (1 << 15) + 7, 9 * (1 << 15) + 3])
def test_segment_lengths_are_each_segments_own(n_points):
    """`polylines.segment_lengths`, split in blocks over the worker threads, gives every segment the length computed
    on its own (the same bytes), a cyclic curve's last point its closing segment and an open curve's last point 0."""
    rng = np.random.default_rng(n_points)
    cuts = np.unique(np.concatenate(([0, n_points], rng.integers(1, n_points, max(1, n_points // 40)))))
    lines = Polylines.build(rng.normal(size=(n_points, 3)), cuts, cyclic=rng.random(len(cuts) - 1) < 0.5)
    pts = lines.points
    d = pts[1:] - pts[:-1]
    want = np.append(np.sqrt(np.einsum("ij,ij->i", d, d)), 0.0)
    ends, starts = lines.offsets[1:] - 1, lines.offsets[:-1]
    closing = pts[starts] - pts[ends]
    want[ends] = np.where(lines.cyclic, np.sqrt(np.einsum("ij,ij->i", closing, closing)), 0.0)
    assert np.array_equal(segment_lengths(lines), want)

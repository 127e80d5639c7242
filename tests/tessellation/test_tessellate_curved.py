"""PN and Phong on whole meshes: crack-free levels, closed output with sharp edges, determinism."""

import numpy as np
import pytest
from mesh_checks import edge_use_counts, is_closed_oriented_manifold
from tessera.kernels.common.camera import Camera
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.common.mesh_arrays import MeshArrays
from tessera.kernels.common.normals import face_unit_normals
from tessera.kernels.common.topology import triangle_edges
from tessera.kernels.tessellation import surface_eval
from tessera.kernels.tessellation.adaptive import METRICS, AdaptiveSettings, adaptive_levels, face_side_edge_levels
from tessera.kernels.tessellation.tessellate import SurfaceOptions, tessellate, uniform_levels
from tessera.tools.generators import octahedron, random_closed


def sharp_mesh(seed):
    """A jittered torus whose faces are flat-shaded on one half and smooth on the other: sharp edges."""
    v, f = random_closed(seed, 7, 5)
    rng = np.random.default_rng(seed)
    face_n = face_unit_normals(v, f)
    smooth = np.zeros((len(v), 3))
    np.add.at(smooth, f.ravel(), np.repeat(face_n, 3, axis=0))
    smooth /= np.linalg.norm(smooth, axis=1, keepdims=True)
    flat = rng.random(len(f)) < 0.5
    corner = np.where(flat[:, None, None], face_n[:, None, :], smooth[f])
    uv = rng.random((len(f), 3, 2)).astype(np.float32)
    return MeshArrays(positions=v, triangles=f, corner_normals=corner.astype(np.float32),
                      corner_attributes={"uv": uv})


def random_camera(rng, target=(0.0, 0.0, 0.0)):
    direction = rng.normal(size=3)
    eye = np.asarray(target) + direction / np.linalg.norm(direction) * rng.uniform(1.5, 8.0)
    return Camera.looking_at(eye, target, fov_deg=rng.uniform(20, 80), width=int(rng.integers(200, 1920)),
                             height=int(rng.integers(200, 1080)))


@pytest.mark.parametrize("seed", range(6))
def test_shared_edge_levels_agree_bit_for_bit(seed):
    mesh = sharp_mesh(seed)
    rng = np.random.default_rng(100 + seed)
    _, face_edges, _ = triangle_edges(mesh.triangles)
    for _ in range(5):
        camera = random_camera(rng)
        for metric in METRICS:
            settings = AdaptiveSettings(metrics=(metric,), max_level=float(rng.integers(2, 65)), edge_pixels=6.0,
                                        near=0.5, far=10.0, power_of_two=str(rng.choice(["NONE", "CEIL"])))
            edge, inner = adaptive_levels(mesh.positions, mesh.triangles, settings, camera, mesh.corner_normals)
            sides = face_side_edge_levels(mesh.positions, mesh.triangles, settings, camera, mesh.corner_normals)
            assert np.array_equal(sides, edge[face_edges]), metric
            assert np.all(inner >= edge[face_edges].max(axis=1))
            assert edge.min() >= 1 and edge.max() <= settings.max_level


@pytest.mark.parametrize("method", ["PN", "PHONG"])
@pytest.mark.parametrize("seed", range(4))
def test_sharp_closed_mesh_gives_closed_output_from_random_cameras(method, seed):
    mesh = sharp_mesh(seed)
    rng = np.random.default_rng(seed)
    for spacing in ("EQUAL", "FRACTIONAL_EVEN"):
        camera = random_camera(rng)
        settings = AdaptiveSettings(metrics=("PROJECTED", "SILHOUETTE", "CURVATURE"), max_level=12, edge_pixels=20)
        edge, inner = adaptive_levels(mesh.positions, mesh.triangles, settings, camera, mesh.corner_normals)
        result = tessellate(mesh, edge, inner, spacing=spacing, method=method, backend="numpy")
        out = result.mesh
        assert is_closed_oriented_manifold(out.triangles)
        assert np.all(np.isfinite(out.positions))
        assert out.corner_normals is not None  # the sharp edges keep their split shading
        np.testing.assert_allclose(np.linalg.norm(out.corner_normals, axis=-1), 1.0, atol=1e-6)
        np.testing.assert_allclose(np.linalg.norm(out.point_normals, axis=-1), 1.0, atol=1e-6)
        assert result.opened_edges == 0


def test_split_mode_opens_the_sharp_edges_and_says_so():
    mesh = sharp_mesh(1)
    levels = uniform_levels(mesh, 4)
    result = tessellate(mesh, levels, method="PN", options=SurfaceOptions(normal_mode="SPLIT"), backend="numpy")
    assert result.opened_edges > 0 and result.notes
    _, counts = edge_use_counts(result.mesh.triangles)
    assert (counts == 1).sum() == 2 * result.opened_edges * 4  # each opened edge: two borders of 4 segments
    assert result.mesh.corner_normals is None  # every vertex has one normal after the split


def test_smooth_mesh_writes_point_normals_only():
    v, f = octahedron()
    mesh = MeshArrays(positions=v, triangles=f, corner_normals=(v[f] / np.linalg.norm(v[f], axis=-1, keepdims=True)))
    out = tessellate(mesh, uniform_levels(mesh, 6), method="PN", backend="numpy").mesh
    assert out.corner_normals is None and out.point_normals.shape == out.positions.shape


@pytest.mark.parametrize("method", ["PN", "PHONG"])
def test_curved_methods_round_an_octahedron_toward_its_sphere(method):
    v, f = octahedron()
    normals = v / np.linalg.norm(v, axis=1, keepdims=True)
    mesh = MeshArrays(positions=v, triangles=f, corner_normals=normals[f])
    flat = tessellate(mesh, uniform_levels(mesh, 8), backend="numpy").mesh
    curved = tessellate(mesh, uniform_levels(mesh, 8), method=method, backend="numpy").mesh
    err_flat = np.abs(np.linalg.norm(flat.positions, axis=1) - 1).mean()
    err_curved = np.abs(np.linalg.norm(curved.positions, axis=1) - 1).mean()
    assert err_curved < 0.6 * err_flat


@pytest.mark.parametrize("method", ["PN", "PHONG", "LINEAR"])
def test_results_are_deterministic(method):
    mesh = sharp_mesh(3)
    levels = np.random.default_rng(0).uniform(1, 9, len(triangle_edges(mesh.triangles)[0]))
    runs = [tessellate(mesh, levels, method=method, backend="numpy").mesh for _ in range(2)]
    for name in ("positions", "triangles", "corner_normals", "point_normals"):
        a, b = getattr(runs[0], name), getattr(runs[1], name)
        assert (a is None and b is None) or a.tobytes() == b.tobytes(), name


@pytest.mark.parametrize("method", ["PN", "PHONG", "LINEAR"])
def test_worker_threads_do_not_change_the_bytes(method, monkeypatch):
    """Positions, normals and attributes are computed side by side; run one after another, the same bytes."""
    from concurrent.futures import Future

    from tessera.kernels.common import workers

    mesh = sharp_mesh(4)
    levels = uniform_levels(mesh, 6)
    parallel = tessellate(mesh, levels, method=method, backend="numpy").mesh

    def inline(fn, *args):
        done = Future()
        done.set_result(fn(*args))
        return done

    monkeypatch.setattr(workers, "submit", inline)
    serial = tessellate(mesh, levels, method=method, backend="numpy").mesh
    for name in ("positions", "triangles", "corner_normals", "point_normals"):
        a, b = getattr(parallel, name), getattr(serial, name)
        assert (a is None and b is None) or a.tobytes() == b.tobytes(), name
    assert parallel.corner_attributes["uv"].tobytes() == serial.corner_attributes["uv"].tobytes()


def test_parallel_section_holds_blas_to_one_thread():
    threadpoolctl = pytest.importorskip("threadpoolctl")
    from tessera.kernels.common import workers

    def blas_threads():
        return [i["num_threads"] for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas"]

    before = blas_threads()
    with workers.parallel_section():
        assert blas_threads() and set(blas_threads()) == {1}
    assert blas_threads() == before


@pytest.mark.parametrize("method", ["PN", "PHONG"])
def test_class_path_equals_point_path(method, monkeypatch):
    mesh = sharp_mesh(2)
    levels = uniform_levels(mesh, 5)
    by_class = tessellate(mesh, levels, method=method, backend="numpy").mesh
    monkeypatch.setattr(surface_eval, "MAX_CLASSES", -1)
    monkeypatch.setattr(surface_eval, "_class_path", lambda n_classes, n_owners: False)
    by_point = tessellate(mesh, levels, method=method, backend="numpy").mesh
    np.testing.assert_allclose(by_class.positions, by_point.positions, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(by_class.point_normals, by_point.point_normals, rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize("unit", [False, True])
@pytest.mark.parametrize("basis_name", ["cubic_basis", "quadratic_basis", "linear_basis"])
def test_point_path_is_the_einsum_bit_for_bit(basis_name, unit, monkeypatch):
    """The point path (owners' controls repeated over their runs, summed term by term) gives the bytes of the
    plain ``einsum("nk,nkc->nc")`` over gathered controls, normalised or not: owners of 0 to 70 points (some empty,
    runs across chunk borders), signed zeros in the controls."""
    from tessera.kernels.tessellation import patches
    from tessera.kernels.tessellation.interpolate import normalize_channels

    monkeypatch.setattr(surface_eval, "CHUNK", 64)  # many chunks, owners split between them
    monkeypatch.setattr(surface_eval, "_class_path", lambda n_classes, n_owners: False)
    basis = getattr(patches, basis_name)
    rng = np.random.default_rng(3)
    counts = rng.integers(0, 70, 40)
    counts[[0, 7, 8]] = 0
    n, k = int(counts.sum()), basis(np.ones((1, 3))).shape[1]
    bary = rng.dirichlet((1, 1, 1), n)
    control = rng.normal(size=(len(counts), k, 3))
    control[rng.random(control.shape) < 0.2] = -0.0
    bary[rng.random(n) < 0.1] = (1.0, 0.0, 0.0)  # a corner: every other term's product is a signed zero
    out = np.empty((n + 5, 3), np.float32)
    keys = np.arange(len(counts), dtype=np.float64)
    surface_eval._evaluate_group(out, 5, counts, keys, None, lambda: bary, control, basis, unit)
    owner = np.repeat(np.arange(len(counts)), counts)
    want = np.einsum("nk,nkc->nc", basis(bary), control[owner])
    if unit:
        normalize_channels([want[:, c] for c in range(3)])
    assert out[5:].tobytes() == want.astype(np.float32).tobytes()


@pytest.mark.parametrize("method", ["PN", "PHONG"])
@pytest.mark.parametrize("flat_share", [0.5, 1.0])
def test_split_corner_normals_per_class_equal_the_general_path(method, flat_share, monkeypatch):
    """Split faces' normal fields evaluated once per vertex slot and stamped equal the per-corner evaluation of the
    general refinement; positions and topology are the same bytes (flat_share 1.0: every face flat, Add > Monkey)."""
    from tessera.kernels.tessellation import refine_templates

    mesh = sharp_mesh(5)
    if flat_share == 1.0:
        face_n = face_unit_normals(mesh.positions, mesh.triangles)
        mesh.corner_normals = np.repeat(face_n[:, None, :], 3, axis=1).astype(np.float32)
    levels = uniform_levels(mesh, 6)
    levels[::4] = 3.0  # several classes, faces of a class not consecutive
    by_class = tessellate(mesh, levels, method=method, backend="numpy")
    assert len(by_class.refinement.classes) > 1
    monkeypatch.setattr(refine_templates, "worth_it", lambda classes, n: False)
    general = tessellate(mesh, levels, method=method, backend="numpy")
    assert not general.refinement.classes
    assert by_class.mesh.positions.tobytes() == general.mesh.positions.tobytes()
    assert by_class.mesh.triangles.tobytes() == general.mesh.triangles.tobytes()
    np.testing.assert_allclose(by_class.mesh.corner_normals, general.mesh.corner_normals, rtol=0, atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(by_class.mesh.corner_normals, axis=2), 1.0, atol=1e-6)


def test_per_vertex_alpha_attribute():
    mesh = sharp_mesh(4)
    levels = uniform_levels(mesh, 4)
    mesh.point_attributes["shape"] = np.full(len(mesh.positions), 0.75, np.float32)
    constant = tessellate(mesh, levels, method="PHONG", backend="numpy").mesh
    per_vertex = tessellate(mesh, levels, method="PHONG", options=SurfaceOptions(alpha_attribute="shape"),
                            backend="numpy").mesh
    np.testing.assert_allclose(per_vertex.positions, constant.positions, atol=2e-6)
    mesh.point_attributes["shape"] = np.zeros(len(mesh.positions), np.float32)
    zero = tessellate(mesh, levels, method="PHONG", options=SurfaceOptions(alpha_attribute="shape"),
                      backend="numpy").mesh
    linear = tessellate(mesh, levels, backend="numpy").mesh
    np.testing.assert_allclose(zero.positions, linear.positions, atol=2e-6)
    with pytest.raises(InvalidInputError, match="shape-factor"):
        tessellate(mesh, levels, method="PHONG", options=SurfaceOptions(alpha_attribute="missing"))


def test_camera_metrics_need_a_camera():
    mesh = sharp_mesh(0)
    with pytest.raises(InvalidInputError, match="camera"):
        adaptive_levels(mesh.positions, mesh.triangles, AdaptiveSettings(metrics=("PROJECTED",)))
    edge, _ = adaptive_levels(mesh.positions, mesh.triangles, AdaptiveSettings(metrics=("CURVATURE",)))
    assert edge.min() >= 1

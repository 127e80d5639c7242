"""One-point parametric surfaces ([Nunes 2011, §2.3]): the coded equations' identities, the pattern counts, the
welded meshes' topology (closed where the surface closes, the Euler characteristic of its topology, outward
orientation), the many-instances path and Table 2.2's accounting."""

import numpy as np
import pytest
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.surfaces import domain_mesh, parametric


def random_uv(seed, n=2000):
    rng = np.random.default_rng(seed)
    return rng.random(n), rng.random(n)


def test_the_coded_equations_satisfy_their_identities():
    u, v = random_uv(0)
    p = parametric.Sphere().point(u, v)
    assert np.abs(np.linalg.norm(p, axis=1) - 1.0).max() < 1e-12
    x, y, z = parametric.Torus().point(u, v).T
    assert np.abs((np.hypot(x, y) - 1.0) ** 2 + z * z - 0.25).max() < 1e-12
    x, y, z = parametric.Cone().point(u, v).T
    assert np.abs(np.hypot(x, y) - 0.5 * (1 - z / 1.5)).max() < 1e-12 and z.min() >= 0 and z.max() <= 1.5
    x, y, z = parametric.Steiner().point(u, v).T
    assert np.abs(x * x * y * y + y * y * z * z + z * z * x * x - x * y * z).max() < 1e-15


def test_the_printed_steiner_equation_is_the_typo():
    """[Nunes 2011, correction 1]: the printed y = a² sin u sin v / 2 does not satisfy the implicit equation; the coded
    one does."""
    u, v = random_uv(1)
    uu, vv = np.pi * u, np.pi * v
    x, z = np.cos(vv) ** 2 * np.sin(2 * uu) / 2, np.cos(uu) * np.sin(2 * vv) / 2
    y_printed = np.sin(uu) * np.sin(vv) / 2
    assert np.abs(x * x * y_printed ** 2 + y_printed ** 2 * z * z + z * z * x * x - x * y_printed * z).max() > 1e-3


@pytest.mark.parametrize("factor", [1, 2, 7, 64])
def test_a_patch_of_factor_f_has_2f2_triangles(factor):
    uv, tris = domain_mesh.domain_pattern(factor)
    assert domain_mesh.pattern_counts(factor) == (len(uv), len(tris)) == ((factor + 1) ** 2, 2 * factor ** 2)
    assert uv.min() == 0 and uv.max() == 1
    a, b = uv[tris[:, 1]] - uv[tris[:, 0]], uv[tris[:, 2]] - uv[tris[:, 0]]
    area = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    assert np.allclose(area, 1.0 / factor ** 2)  # counter-clockwise, the square tiled exactly
    assert domain_mesh.pattern_counts(64)[1] == 8192  # [Nunes 2011]'s torus


def edge_uses(tris):
    e = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return counts


def signed_volume(mesh):
    p = mesh.positions.astype(np.float64)[mesh.triangles]
    return np.einsum("ti,ti->t", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum() / 6.0


# (surface, Euler characteristic, boundary edges as a function of F, orientable and closed)
TOPOLOGY = [
    ("SPHERE", 2, lambda f: 0, True),
    ("SUPERELLIPSOID", 2, lambda f: 0, True),
    ("TORUS", 0, lambda f: 0, True),
    ("TREFOIL", 0, lambda f: 0, True),
    ("KLEIN", 0, lambda f: 0, False),
    ("STEINER", 1, lambda f: 0, False),
    ("CONE", 1, lambda f: f, False),
    ("MOBIUS", 0, lambda f: 2 * f, False),
]


@pytest.mark.parametrize("factor", [8, 16])
@pytest.mark.parametrize("name,chi,boundary,orientable_closed", TOPOLOGY)
def test_welded_meshes_have_their_surfaces_topology(name, chi, boundary, orientable_closed, factor):
    surface = parametric.SURFACES[name]()
    mesh = domain_mesh.surface_mesh(surface, factor)
    uses = edge_uses(mesh.triangles)
    assert uses.max() == 2 and int((uses == 1).sum()) == boundary(factor)
    n_edges = len(uses)
    assert len(mesh.positions) - n_edges + len(mesh.triangles) == chi
    assert len(np.unique(mesh.triangles)) == len(mesh.positions)  # no unused vertex
    # every vertex sits where the formula puts its domain point
    uv, _ = domain_mesh.domain_pattern(factor)
    src = uv[mesh.source].astype(np.float64)
    assert np.allclose(mesh.positions, surface.point(src[:, 0], src[:, 1]), atol=1e-6)
    # corner UVs are the domain coordinates of the corner: the corner's vertex is at that point
    corner = surface.point(mesh.uvs[..., 0].astype(np.float64), mesh.uvs[..., 1].astype(np.float64))
    assert np.abs(corner - mesh.positions[mesh.triangles]).max() < 1e-5
    if orientable_closed:
        assert signed_volume(mesh) > 0  # outward


def test_the_cone_faces_out():
    """An open surface: the cone's normals point away from its axis."""
    mesh = domain_mesh.surface_mesh(parametric.Cone(), 16)
    p = mesh.positions.astype(np.float64)[mesh.triangles]
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    radial = p.mean(axis=1) * [1, 1, 0]
    assert (np.einsum("ti,ti->t", n, radial) > 0).all()


@pytest.mark.parametrize("name", sorted(parametric.SURFACES))
def test_bad_parameters_and_factors_are_refused(name):
    cls = parametric.SURFACES[name]
    field = next(iter(cls.__dataclass_fields__))
    with pytest.raises(InvalidInputError):
        domain_mesh.surface_mesh(cls(**{field: float("nan")}), 4)
    with pytest.raises(InvalidInputError):
        domain_mesh.surface_mesh(cls(), 0)
    with pytest.raises(InvalidInputError):
        domain_mesh.surface_mesh(cls(), 65)


def test_many_instances_and_table_2_2():
    rng = np.random.default_rng(3)
    cps = rng.uniform(-10, 10, (5, 3))
    torus = parametric.Torus()
    pos = domain_mesh.instance_positions(torus, 8, cps).reshape(5, -1, 3)
    uv, _ = domain_mesh.domain_pattern(8)
    local = torus.point(uv[:, 0].astype(np.float64), uv[:, 1].astype(np.float64))
    assert np.allclose(pos - cps[:, None, :], local[None], atol=1e-5)
    # Table 2.2: 20000 tori of 8192 triangles: 5898.24 MB as a non-indexed buffer, 0.24 MB as control points
    mesh_bytes, point_bytes = domain_mesh.upload_bytes(20000, 64)
    assert (mesh_bytes, point_bytes) == (5_898_240_000, 240_000)
    assert domain_mesh.upload_bytes(5000, 64)[0] == 1_474_560_000  # [Nunes 2011, correction 5]: 1474.56, not 1479.56


def test_debug_colour():
    p = parametric.Sphere().point(*random_uv(4, 10))
    assert np.allclose(parametric.debug_colour(parametric.Sphere(), p), p + 0.6)
    q = parametric.Torus().point(*random_uv(5, 10))
    assert np.allclose(parametric.debug_colour(parametric.Torus(), q), q / np.linalg.norm(q, axis=1)[:, None] + 0.4)


def test_camera_factors_fall_with_distance():
    from tessera.kernels.common import camera

    cam = camera.Camera(camera.look_at_view((0, -10, 0), (0, 0, 0)), camera.perspective(0.8, 1.0, 0.1, 1e4), 512, 512)
    points = np.array([[0, 0, 0], [0, 20, 0], [0, 200, 0], [0, 2000, 0], [0, -20, 0]], np.float64)
    f = domain_mesh.camera_factors(parametric.Torus(), points, cam, edge_pixels=4.0)
    assert f[0] >= f[1] >= f[2] >= f[3] and f[0] > f[3] and f[4] == 1  # behind the eye: 1
    assert f.min() >= 1 and f.max() <= domain_mesh.MAX_FACTOR
    # radius in pixels at depth 10: 1.5 * focal / 10 with focal = 256 / tan(0.4)
    r_px = domain_mesh.bounding_radius(parametric.Torus()) * 256 / np.tan(0.4) / 10
    assert f[0] == min(64, int(np.ceil(2 * np.pi * r_px / 4.0)))


def test_quarter_turns_are_exact():
    t = np.array([0.0, 0.25, 0.5, 0.75, 1.0, -0.25, 0.125])
    c, s = parametric.cos_sin_turns(t)
    assert np.array_equal(c[:6], [1, 0, -1, 0, 1, 0]) and np.array_equal(s[:6], [0, 1, 0, -1, 0, -1])
    assert np.allclose([c[6], s[6]], [np.cos(np.pi / 4), np.sin(np.pi / 4)], atol=1e-15)
    u, v = random_uv(6)
    c, s = parametric.cos_sin_turns(u)
    assert np.allclose(c, np.cos(2 * np.pi * u), atol=1e-15) and np.allclose(s, np.sin(2 * np.pi * u), atol=1e-15)
    poles = parametric.Superellipsoid(e1=0.3, e2=0.3).point(np.array([0.0, 1.0]), np.array([0.3, 0.7]))
    assert np.array_equal(poles, [[0, 0, 1], [0, 0, -1]])  # no sqrt(6e-17) offsets

"""Bicubic Bézier patches with per-boundary levels ([Nellmedin 2014, §4.3, §5.5.3]) on the teapot's body of
revolution: welded with no crack or T-junction at any levels, every vertex on its patch, the curvature levels
highest at the knob and the base, distance levels high near and low far."""

import numpy as np
import pytest
from tessera.kernels.common import camera
from tessera.kernels.common.errors import InvalidInputError, OpenCLUnavailableError
from tessera.kernels.surfaces import bezier_patches as bp
from tessera.kernels.surfaces.bezier_patches import deviation

from tools.revolved_teapot import teapot_patches

pytestmark = pytest.mark.usefixtures("numpy_reference")  # the numpy reference; OpenCL: test_opencl_surfaces.py


def edge_uses(tris):
    e = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    keys, counts = np.unique(e, axis=0, return_counts=True)
    return keys, counts


def open_boundary_levels(patches, edges, edge_levels):
    """Segments on the teapot's two open circles (the rim's inner edge r = 1.4 and the lid's edge r = 1.3, z 2.4)."""
    c = bp.cartesian(edges.control)
    r = np.hypot(c[:, 0, 0], c[:, 0, 1])
    on = np.all(np.isclose(c[:, :, 2], 2.4), axis=1) & (np.isclose(r, 1.4) | np.isclose(r, 1.3))
    return int(edge_levels[on].sum())


def check_mesh(patches, edges, edge_levels, inner, mesh):
    keys, counts = edge_uses(mesh.triangles)
    assert counts.max() == 2
    assert int((counts == 1).sum()) == open_boundary_levels(patches, edges, edge_levels)  # no crack anywhere else
    on = bp.evaluate(patches[mesh.patch], mesh.uv[:, None, 0].astype(np.float64), mesh.uv[:, None, 1])[:, 0]
    assert np.abs(on - mesh.positions).max() < 1e-5  # every vertex on its patch
    corner = bp.evaluate(patches[mesh.triangle_patch], mesh.corner_uv[..., 0].astype(np.float64),
                         mesh.corner_uv[..., 1].astype(np.float64))
    assert np.abs(corner - mesh.positions[mesh.triangles]).max() < 1e-5  # corner UVs: where each corner is
    p = mesh.positions.astype(np.float64)[mesh.triangles]
    area = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    assert (area > 0).all()


def test_uniform_levels_give_2l2_triangles_per_patch_and_weld():
    patches, _ = teapot_patches()
    edges = bp.patch_edges(patches)
    assert len(edges.control) < 4 * len(patches)  # shared sides are one edge
    for level in (1, 2, 5, 8):
        el, inner = np.full(len(edges.control), level), np.full(len(patches), level)
        mesh = bp.tessellate_patches(patches, el, inner, edges)
        collapsed = 8 * level if level > 1 else 8  # the lid's top and the bottom's centre: one triangle per step lost
        assert len(mesh.triangles) == 24 * 2 * level * level - collapsed or level == 1
        check_mesh(patches, edges, el, inner, mesh)


def test_random_levels_stay_welded():
    patches, _ = teapot_patches()
    edges = bp.patch_edges(patches)
    rng = np.random.default_rng(0)
    for _ in range(10):
        el = rng.integers(1, 20, len(edges.control))
        inner = rng.integers(1, 20, len(patches))
        check_mesh(patches, edges, el, inner, bp.tessellate_patches(patches, el, inner, edges))


def test_curvature_levels_are_highest_at_the_knob_and_the_base():
    patches, names = teapot_patches()
    edges = bp.patch_edges(patches)
    el, inner = bp.patch_levels(patches, edges, bp.PatchLod(metrics=("CURVATURE",)))
    by = {n: inner[names == n].max() for n in set(names)}
    top_two = sorted(by, key=by.get, reverse=True)[:2]
    assert set(top_two) == {"lid_top", "bottom"}, by
    assert el.min() >= 6 and el.max() <= 32 and inner.max() == 32
    # without [Nellmedin 2014]'s cap for collapsed rows the base is an ordinary patch; the knob still folds
    _, geometric = bp.patch_levels(patches, edges, bp.PatchLod(metrics=("CURVATURE",), degenerate="ZERO"))
    assert geometric[names == "lid_top"].max() > geometric[names != "lid_top"].max()
    assert geometric[names == "bottom"].max() < inner[names == "bottom"].max()


def test_distance_levels_high_near_low_far_and_welded_from_20_cameras():
    patches, _ = teapot_patches()
    edges = bp.patch_edges(patches)
    lod = bp.PatchLod(metrics=("DISTANCE",), max_level=24, near=2.0, far=30.0)
    el, inner = bp.patch_levels(patches, edges, lod, looking((0, -1.9, 1.5)))  # inside the near distance: all high
    assert el.min() >= 20 and inner.min() >= 20
    el, inner = bp.patch_levels(patches, edges, lod, looking((0, -300, 1.5)))
    assert el.max() == 1 and inner.max() == 1
    rng = np.random.default_rng(4)
    every = bp.PatchLod(metrics=bp.METRICS, near=2.0, far=30.0, edge_pixels=12.0)
    for _ in range(20):
        d = rng.normal(size=3)
        el, inner = bp.patch_levels(patches, edges, every, looking(rng.uniform(3, 25) * d / np.linalg.norm(d)))
        check_mesh(patches, edges, el, inner, bp.tessellate_patches(patches, el, inner, edges))


def looking(eye, target=(0.0, 0.0, 1.5), size=512):
    return camera.Camera(camera.look_at_view(eye, target), camera.perspective(0.8, 1.0, 0.05, 1e4), size, size)


def test_projected_edge_levels_follow_the_screen():
    patches, _ = teapot_patches()
    edges = bp.patch_edges(patches)
    lod = bp.PatchLod(metrics=("EDGE_LENGTH",), max_level=64, edge_pixels=8.0)
    near = bp.patch_levels(patches, edges, lod, looking((0, -8, 1.5)))
    far = bp.patch_levels(patches, edges, lod, looking((0, -40, 1.5)))
    small = bp.patch_levels(patches, edges, lod, looking((0, -8, 1.5), size=128))
    assert near[0].sum() > 3 * far[0].sum() and near[0].sum() > 2 * small[0].sum()
    # a side's level is its control polygon's projected length over Edge Pixels (never below 1)
    c = bp.cartesian(edges.control)
    length = np.linalg.norm(np.diff(c, axis=1), axis=2).sum(axis=1)
    cam = looking((0, -8, 1.5))
    m = c.mean(axis=1) @ np.asarray(cam.view)[:3, :3].T + np.asarray(cam.view)[:3, 3]
    focal = 0.5 * 512 * np.asarray(cam.projection)[1, 1]
    approx = focal * length / -m[:, 2] / 8.0  # the sphere's projected diameter, to first order
    assert np.allclose(near[0], np.clip(np.ceil(approx), 1, 64), atol=1.0)


def test_both_sides_of_an_edge_get_one_level_and_bad_input_is_refused():
    patches, _ = teapot_patches()
    edges = bp.patch_edges(patches)
    # the same edge seen from two patches: its control points, reversed on one side
    count = np.bincount(edges.edge.ravel())
    collapsed = np.all(edges.control == edges.control[:, :1], axis=(1, 2))
    assert collapsed.sum() == 2 and (count[collapsed] == 4).all()  # the lid's top, the bottom's centre
    assert (count[~collapsed] <= 2).all() and (count == 2).sum() > 30
    with pytest.raises(InvalidInputError):
        bp.patch_levels(patches, edges, bp.PatchLod(metrics=("DISTANCE",)))
    with pytest.raises(InvalidInputError):
        bp.check_patches(np.full((1, 4, 4, 3), np.nan))
    with pytest.raises(InvalidInputError):
        bp.PatchLod(metrics=("FAST",))


def full_teapot():
    from tools.utah_teapot import teapot_patches as full

    return full()


def test_the_full_teapot_welds_where_its_patches_share_sides():
    patches, parts = full_teapot()
    assert patches.shape == (32, 4, 4, 3) and list(dict.fromkeys(parts)) == list(
        ("rim", "body_upper", "body_lower", "handle", "spout", "lid_top", "lid_bottom", "bottom"))
    edges = bp.patch_edges(patches)
    assert edges.collapsed.sum() == 2  # the lid's top, the bottom's centre
    mesh = bp.tessellate_patches(patches, np.full(len(edges.control), 5), np.full(len(patches), 5), edges)
    _, counts = edge_uses(mesh.triangles)
    assert counts.max() == 2
    # open: the rim's inside, the lid's edge (4 sides each), the handle's and the spout's two ends (2 sides each)
    assert (counts == 1).sum() == 5 * (4 + 4 + 2 * 2 + 2 * 2)
    n = mesh.normals.astype(np.float64)
    body = np.isin(mesh.patch, np.flatnonzero(np.isin(parts, ("body_upper", "body_lower"))))
    out = mesh.positions[body] * [1, 1, 0]
    assert (np.einsum("ij,ij->i", n[body], out) > 0).all()  # normals point out of the body


def test_anisotropic_levels_and_splitting_meet_the_tolerance_and_stay_welded():
    patches, _ = full_teapot()
    tol = 2e-3
    # Max Level 6 cannot reach the tolerance on whole patches: patches over it are split (with their neighbours
    # along the split sides) until it is met
    r = bp.tessellate_surface(patches, bp.PatchLod(metrics=("TOLERANCE",), tolerance=tol, max_level=6))
    assert len(r.parent) > len(patches) and len(r.unmet) == 0 and r.deviation.max() <= tol
    _, counts = edge_uses(r.mesh.triangles)
    assert counts.max() == 2
    # every vertex on the teapot at its patch's (u, v), through the parts' boxes
    uv = r.patch_uv()
    want = bp.evaluate(patches[r.parent[r.mesh.triangle_patch]], uv[..., 0], uv[..., 1])
    assert np.abs(want - r.mesh.positions[r.mesh.triangles]).max() < 1e-5
    # the inside of a patch steps each way on its own: the spout's patches are long and thin
    whole = bp.tessellate_surface(patches, bp.PatchLod(metrics=("TOLERANCE",), tolerance=tol, max_level=64))
    assert (whole.inner_levels[:, 0] != whole.inner_levels[:, 1]).any() and len(whole.parent) == len(patches)
    assert whole.deviation.max() <= tol and len(whole.unmet) == 0


def test_split_parts_lie_on_their_patches_and_keep_shared_sides():
    from tessera.kernels.surfaces import patch_split as sp

    patches, _ = full_teapot()
    h = bp.check_patches(patches)
    edges = bp.patch_edges(h)
    rng = np.random.default_rng(0)
    counts = sp.consistent_counts(rng.integers(1, 4, (len(h), 2)), edges.edge, edges.reversed)
    parts, parent, box = sp.split_patches(h, counts, edges)
    assert len(parts) == counts.prod(axis=1).sum()
    s, t = rng.random((len(parts), 5)), rng.random((len(parts), 5))
    u = box[:, 0, :1] + s * (box[:, 0, 1:] - box[:, 0, :1])
    v = box[:, 1, :1] + t * (box[:, 1, 1:] - box[:, 1, :1])
    assert np.abs(bp.evaluate(parts, s, t) - bp.evaluate(h[parent], u, v)).max() < 1e-12
    split_edges = bp.patch_edges(parts)
    mesh = bp.tessellate_patches(parts, np.full(len(split_edges.control), 3), np.full(len(parts), 3), split_edges)
    _, uses = edge_uses(mesh.triangles)
    # open sides only where the whole patches had them, each cut into its parts
    once = np.bincount(edges.edge.ravel(), minlength=len(edges.control)) == 1
    want = sum(3 * counts[q, sp.SIDE_AXIS[side]] for q in range(len(h)) for side in range(4)
               if once[edges.edge[q, side]] and not edges.collapsed[edges.edge[q, side]])
    assert uses.max() == 2 and (uses == 1).sum() == want


def test_patches_that_share_a_side_put_its_steps_where_their_grids_put_theirs():
    patches, _ = full_teapot()
    h = bp.check_patches(patches)
    edges = bp.patch_edges(h)
    spacing = bp.patch_spacing(h, edges)
    for level in (3, 17, 40):
        side_t = spacing.side_params(np.full(len(edges.control), level))
        for p in range(len(h)):
            for side in range(4):
                e = edges.edge[p, side]
                if edges.collapsed[e]:
                    continue
                inner = spacing.inner_params(np.array([p]), side % 2, level)[0]
                along = 1.0 - side_t[e, ::-1] if edges.reversed[p, side] else side_t[e]
                assert np.abs(along - inner).max() < 1e-12
    # a half-twisted loop (a Möbius band of bilinear patches) meets its own chain reversed: its steps read the
    # same both ways
    angle = np.linspace(0, 2 * np.pi, 5)

    def at(a, w):
        return [np.cos(a) * (1 + w * np.cos(a / 2)), np.sin(a) * (1 + w * np.cos(a / 2)), w * np.sin(a / 2)]

    band = np.array([[[at(angle[i + di], w) for w in (-0.5, 0.5)] for di in (0, 1)] for i in range(4)])
    band[3, 1] = band[0, 0, ::-1]  # the last side is the first, turned over (exactly, as a closed band shares it)
    twisted = bp.patch_edges(band)
    chain, flip, _, _, two_way = bp.direction_chains(twisted, len(band))
    assert len(set(chain[:, 1])) == 1 and two_way[chain[0, 1]]
    assert not two_way[chain[:, 0]].any()
    table = bp.patch_spacing(bp.check_patches(band), twisted).inner[:, 1]
    assert np.abs(table - (1.0 - table[:, ::-1])).max() < 1e-12


def test_strips_zipped_by_parameter_are_valid_and_equal_the_pattern_on_equal_steps():
    from tessera.kernels.common import quad_pattern as qp

    rng = np.random.default_rng(5)
    for p, q in ((3, 5), (9, 2), (6, 6), (1, 4)):
        outer, inner = np.arange(p + 1), 100 + np.arange(q + 1)
        even = qp.zip_by_params(outer, inner, (np.arange(p + 1) / p)[None], (np.arange(q + 1) / q)[None])[0]
        assert sorted(map(tuple, even.tolist())) == sorted(qp._zip(list(outer), list(inner)))
        # random increasing parameters: every triangle counter-clockwise between the rows (outer at y = 0,
        # inner at y = 1), each segment of both rows used once
        t_o = np.sort(np.r_[0, rng.random(p - 1), 1])[None]
        t_i = np.sort(np.r_[0, rng.random(q - 1), 1])[None] * 0.8 + 0.1
        tris = qp.zip_by_params(outer, inner, t_o, t_i)[0]
        pos = {**{int(o): (t_o[0, k], 0.0) for k, o in enumerate(outer)},
               **{int(i): (t_i[0, k], 1.0) for k, i in enumerate(inner)}}
        xy = np.array([[pos[int(v)] for v in tri] for tri in tris])
        e1, e2 = xy[:, 1] - xy[:, 0], xy[:, 2] - xy[:, 0]
        area = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
        assert (area > 0).all() and len(tris) == p + q


def test_fitted_inner_levels_are_the_fewest_cells_of_their_model():
    rng = np.random.default_rng(2)
    tol, most = 1e-3, 64
    for _ in range(40):
        a, b, c = rng.uniform(0, 0.3, 3) * [1, 1, rng.choice([0, 1])]
        n0 = rng.integers(3, 30, 2)
        measured = np.array([[a / n0[0] ** 2 + b / n0[1] ** 2 + c / (n0[0] * n0[1]), a / n0[0] ** 2,
                              b / n0[1] ** 2]])
        fit = bp.fitted_inner(measured, n0[None], tol, most)[0]
        n, m = np.meshgrid(np.arange(1, most + 1), np.arange(1, most + 1), indexing="ij")
        model = a / n ** 2 + b / m ** 2 + c / (n * m)
        aim = bp.FIT_AIM * tol
        if (model <= aim).any():
            assert a / fit[0] ** 2 + b / fit[1] ** 2 + c / (fit[0] * fit[1]) <= aim * (1 + 1e-9)
            assert fit.prod() == (n * m)[model <= aim].min()


def test_the_sides_measured_without_a_mesh_are_the_meshes_and_the_deviation_is_the_meshes():
    patches, _ = full_teapot()
    h = bp.check_patches(patches)
    tol = 1e-3
    r = bp.tessellate_surface(h, bp.PatchLod(metrics=("TOLERANCE",), tolerance=tol, max_level=64))
    assert len(r.parent) == len(h)  # whole patches
    spacing = bp.patch_spacing(h, r.edges)
    corners, uv, patch = bp.rim_triangles(h, r.edge_levels, r.inner_levels, r.edges, spacing, np.arange(len(h)))
    mesh = r.mesh
    rim = np.flatnonzero(((mesh.corner_uv == 0) | (mesh.corner_uv == 1)).any(axis=(1, 2)))
    assert len(rim) == len(patch)
    on_mesh = np.sort(bp.triangle_deviation(h, mesh, rim))
    assert np.abs(np.sort(deviation._deviation(h, corners, uv, patch)) - on_mesh).max() < 1e-12
    # every triangle of the mesh measured again: within the tolerance and within each patch's recorded deviation
    every = bp.triangle_deviation(h, mesh)
    worst = np.zeros(len(h))
    np.maximum.at(worst, mesh.triangle_patch, every)
    assert every.max() <= tol and (worst <= r.deviation + bp.stored_error(h)).all()


def test_tessellating_on_a_worker_thread_measures_in_place_and_gives_the_same_mesh():
    from tessera.kernels.common import workers

    patches, _ = full_teapot()
    lod = bp.PatchLod(metrics=("TOLERANCE",), tolerance=2e-3, max_level=64)
    here = bp.tessellate_surface(patches, lod)
    # every worker busy with a tessellation that would hand its measuring to the pool: none waits on the others
    there = [workers.submit(bp.tessellate_surface, patches, lod) for _ in range(workers.WORKERS)]
    for future in there:
        mesh = future.result(timeout=120).mesh
        assert np.array_equal(mesh.positions, here.mesh.positions)
        assert np.array_equal(mesh.triangles, here.mesh.triangles)


def test_backends_are_checked():
    h = bp.check_patches(full_teapot()[0][:2])
    lod = bp.PatchLod(metrics=("TOLERANCE",), tolerance=1e-2)
    with pytest.raises(InvalidInputError, match="backend"):
        bp.tessellate_surface(h, lod, backend="cuda")


def test_opencl_asked_for_without_a_device_is_an_error():
    h = bp.check_patches(full_teapot()[0][:2])
    with pytest.raises(OpenCLUnavailableError, match="Tessellate Surface"):
        bp.tessellate_surface(h, bp.PatchLod(metrics=("TOLERANCE",), tolerance=1e-2), backend="opencl")

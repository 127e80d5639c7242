"""Bicubic Bézier patches with per-boundary levels ([Nellmedin 2014, §4.3, §5.5.3]) on the teapot's body of
revolution: welded with no crack or T-junction at any levels, every vertex on its patch, the curvature levels
highest at the knob and the base, distance levels high near and low far."""

import numpy as np
import pytest
from tessera.kernels.common import camera
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.surfaces import bezier_patches as bp
from tessera.kernels.surfaces.revolved_teapot import teapot_patches


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

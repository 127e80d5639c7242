"""The GPU tube preview (instanced ring patterns from section textures) against the numpy tube mesh (tier: gpu)."""

import numpy as np
import pytest

pytestmark = [pytest.mark.blender, pytest.mark.gpu]


def quads_to_tris(mesh):
    off = mesh.face_offsets
    tris = []
    for k in np.unique(mesh.face_sizes):
        faces = np.nonzero(mesh.face_sizes == k)[0]
        idx = mesh.corner_verts[off[faces][:, None] + np.arange(k)]
        tris += [idx[:, [0, i, i + 1]] for i in range(1, k - 1)]
    return np.concatenate(tris)


def scene(seed=3):
    from tessera.kernels.tubes.polylines import Polylines

    rng = np.random.default_rng(seed)
    walks = [np.cumsum(rng.normal(scale=0.3, size=(n, 3)), axis=0) + rng.normal(size=3) for n in (150, 40, 7)]
    s = np.linspace(0, 2 * np.pi, 90, endpoint=False)
    ring = np.stack((1.5 * np.cos(s), 1.5 * np.sin(s), 0.3 * np.sin(3 * s)), axis=1)
    pts = np.concatenate(walks + [ring])
    offsets = np.cumsum([0, 150, 40, 7, 90])
    return Polylines.build(pts, offsets, radius=rng.uniform(0.05, 0.15, len(pts)), cyclic=[False] * 3 + [True])


@pytest.mark.parametrize("sides_mode", ["FIXED", "CAMERA"])
def test_preview_draws_the_same_tubes_as_the_mesh(gpu_renderer, addon_module, sides_mode):
    tubes = addon_module("kernels.tubes.builder")
    preview = addon_module("gpu_shaders.tubes.draw")
    offscreen = addon_module("gpu_shaders.offscreen")
    Camera = addon_module("kernels.common.camera").Camera
    lines = scene()
    settings = tubes.TubeSettings(sides=7, sides_mode=sides_mode, min_sides=3, max_sides=16, edge_pixels=4)
    rng = np.random.default_rng(9)
    for _ in range(3):
        d = rng.normal(size=3)
        cam = Camera.looking_at(8 * d / np.linalg.norm(d), (0, 0, 0), width=200, height=200)
        mesh = tubes.build_tubes(lines, settings, cam)
        vp = cam.projection @ cam.view
        cpu = offscreen.render_triangles(mesh.positions, quads_to_tris(mesh), vp, size=(200, 200),
                                         color=(1, 1, 1, 1), lit=False)
        prepared, frames = tubes.tube_sections(lines, settings, cam)
        data = preview.TubeDrawData(prepared, frames.n, frames.b, frames.radius)
        data.set_sides(tubes.lod_sides(prepared, settings, cam))
        gpu = offscreen.render(lambda data=data, vp=vp: data.draw(vp, 200, color=(1, 1, 1, 1), lit=False),
                               size=(200, 200))
        a, b = cpu[..., 0] > 127, gpu[..., 0] > 127
        assert a.sum() > 2000
        assert np.mean(a == b) >= 0.995, np.mean(a == b)


def test_preview_clamp_keeps_far_tubes_visible_like_the_mesh(gpu_renderer, addon_module):
    tubes = addon_module("kernels.tubes.builder")
    preview = addon_module("gpu_shaders.tubes.draw")
    offscreen = addon_module("gpu_shaders.offscreen")
    Camera = addon_module("kernels.common.camera").Camera
    Polylines = addon_module("kernels.tubes.polylines").Polylines
    x = np.linspace(-30, 30, 40)
    pts = np.concatenate([np.stack((x, np.full(40, 200.0), np.full(40, z)), axis=1) for z in (-20, 0, 20)])
    lines = Polylines.build(pts, [0, 40, 80, 120], radius=1e-3)
    cam = Camera.looking_at((0, 0, 0), (0, 1, 0), width=160, height=160, far=1000)
    vp = cam.projection @ cam.view
    settings = tubes.TubeSettings(sides=6, aa_clamp=True)
    mesh = tubes.build_tubes(lines, settings, cam)
    cpu = offscreen.render_triangles(mesh.positions, quads_to_tris(mesh), vp, size=(160, 160), color=(1, 1, 1, 1),
                                     lit=False)
    prepared, frames = tubes.tube_sections(lines, settings, cam)
    data = preview.TubeDrawData(prepared, frames.n, frames.b, frames.radius)
    data.set_sides(tubes.lod_sides(prepared, settings, cam))
    gpu = offscreen.render(lambda: data.draw(vp, 160, color=(1, 1, 1, 1), lit=False, clamp=True), size=(160, 160))
    a, b = cpu[..., 0] > 127, gpu[..., 0] > 127
    assert a.sum() >= 3 * 100  # three unbroken lines, at least two pixels thick over most of the view
    assert np.mean(a == b) >= 0.995
    thin = offscreen.render(lambda: data.draw(vp, 160, color=(1, 1, 1, 1), lit=False, clamp=False), size=(160, 160))
    assert (thin[..., 0] > 127).sum() < a.sum() / 4  # without the clamp the lines break up


def test_preview_cache_refreshes_only_on_change(gpu_renderer, addon_module, clean_scene, bpy_module):
    bpy = bpy_module
    preview = addon_module("addon.tubes.preview")
    bpy.ops.curve.primitive_bezier_curve_add()
    ob = bpy.context.active_object
    ob.tessera.tubes.preview = True
    bpy.context.view_layer.update()  # settle the updates of adding the curve
    entry = preview.entry_for(ob)
    assert entry is not None and preview.entry_for(ob) is entry  # built once, reused
    assert entry.draw.section_bytes == 48 * (ob.data.resolution_u + 1)
    bpy.context.view_layer.update()
    assert preview.entry_for(ob) is entry  # nothing changed: nothing rebuilt
    ob.data.splines[0].bezier_points[0].co.x += 1.0
    bpy.context.view_layer.update()
    assert ob not in preview.PREVIEW.cache  # an edit drops the uploaded sections
    entry = preview.entry_for(ob)
    ob.tessera.tubes.sides = 5
    assert ob not in preview.PREVIEW.cache  # so does a settings change
    ob.tessera.tubes.preview = False
    bpy.data.curves.remove(ob.data)
    preview.PREVIEW.cache.clear()


@pytest.mark.parametrize("n", [3, 8])
def test_the_preview_wire_is_the_tube_mesh_s_quads_not_their_diagonals(addon_module, n):
    """In Wireframe the preview draws the edges the applied tube mesh has: every side of every quad once (each
    section's ring, each line along the tube), none of the diagonals that split the quads into triangles."""
    draw = addon_module("gpu_shaders.tubes.draw")
    _, tris, edges = draw.ring_pattern(n)
    drawn = {tuple(sorted(e)) for e in edges.tolist()}
    assert len(drawn) == len(edges)  # each once
    quads = tris[: len(tris) // 2]  # (a, a1, a1 + n): a quad's first triangle; the quad is a, a1, a1 + n, a + n
    a, a1 = quads[:, 0], quads[:, 1]
    sides = {tuple(sorted(e)) for e in np.concatenate([np.stack(p, 1) for p in (
        (a, a1), (a1, a1 + n), (a + n, a1 + n), (a, a + n))]).tolist()}
    diagonals = {tuple(sorted(e)) for e in np.stack((a, a1 + n), 1).tolist()}
    assert sides <= drawn and not diagonals & drawn
    assert drawn - sides == set()  # and nothing else: the last section's ring is a quad side too

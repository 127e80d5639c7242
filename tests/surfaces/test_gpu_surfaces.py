"""The one-point GPU path of the parametric surfaces (tier: gpu): the vertices the shader places are the numpy
kernel's (compute shader, same GLSL as the preview), and the instanced preview draws the same picture as the
baked instances uploaded as one mesh."""

import numpy as np
import pytest

pytestmark = [pytest.mark.blender, pytest.mark.gpu]


@pytest.mark.parametrize("name", ["SPHERE", "CONE", "TORUS", "STEINER", "KLEIN", "MOBIUS", "TREFOIL",
                                  "SUPERELLIPSOID"])
def test_gpu_vertices_equal_the_kernels(gpu_renderer, addon_module, name):
    parametric = addon_module("kernels.surfaces.parametric")
    domain_mesh = addon_module("kernels.surfaces.domain_mesh")
    draw = addon_module("gpu_shaders.surfaces.draw")
    surface = parametric.SURFACES[name]()
    points = np.random.default_rng(1).uniform(-5, 5, (7, 3)).astype(np.float32)
    got = draw.evaluate_on_gpu(surface, points, 16)
    want = domain_mesh.instance_positions(surface, 16, points)
    assert got.shape == want.shape
    assert np.abs(got - want).max() <= 2e-6 * (1.0 + np.abs(want).max())
    # and the baked mesh's vertices are among them, at their domain points (first instance, minus its point)
    baked = domain_mesh.surface_mesh(surface, 16)
    first = got[: (16 + 1) ** 2] - points[0]
    assert np.abs(first[baked.source] - baked.positions).max() <= 2e-6 * (1.0 + np.abs(baked.positions).max())


def test_the_instanced_preview_draws_what_the_uploaded_mesh_draws(gpu_renderer, addon_module):
    parametric = addon_module("kernels.surfaces.parametric")
    domain_mesh = addon_module("kernels.surfaces.domain_mesh")
    draw = addon_module("gpu_shaders.surfaces.draw")
    offscreen = addon_module("gpu_shaders.offscreen")
    camera = addon_module("kernels.common.camera")
    torus = parametric.Torus()
    rng = np.random.default_rng(4)
    points = rng.uniform(-6, 6, (12, 3))
    cam = camera.Camera(camera.look_at_view((3, -22, 9), (0, 0, 0)), camera.perspective(0.9, 1.0, 0.1, 100), 200, 200)
    vp = cam.projection @ cam.view
    factors = domain_mesh.camera_factors(torus, points, cam, edge_pixels=6.0)
    assert len(np.unique(factors)) > 1  # several factors: several draws
    data = draw.SurfaceDrawData(torus, points, factors)
    meshes = [domain_mesh.surface_mesh(torus, int(f)) for f in factors]
    positions = np.concatenate([m.positions + p.astype(np.float32) for m, p in zip(meshes, points, strict=True)])
    starts = np.cumsum([0] + [len(m.positions) for m in meshes])[:-1]
    tris = np.concatenate([m.triangles + s for m, s in zip(meshes, starts, strict=True)])
    assert data.triangle_count == sum(2 * int(f) ** 2 for f in factors)
    cpu = offscreen.render_triangles(positions, tris, vp, size=(200, 200), color=(1, 1, 1, 1), lit=False)
    gpu = offscreen.render(lambda: data.draw(vp, color=(1, 1, 1, 1), lit=False), size=(200, 200))
    a, b = cpu[..., 0] > 127, gpu[..., 0] > 127
    assert a.sum() > 1500
    assert np.mean(a == b) >= 0.998, np.mean(a == b)
    # what crossed to the GPU: 16 bytes a control point and the patterns, far less than the mesh
    assert data.uploaded_bytes < positions.nbytes + tris.nbytes


def test_a_live_surface_draws_what_bake_surface_makes(clean_scene, gpu_renderer, bpy_module, addon_module):
    """Add > Parametric Surface (Live): an empty with no mesh, drawn at every vertex of a control mesh by the
    preview; Bake Surface makes the same surfaces as a mesh: both pictures agree."""
    bpy = bpy_module
    preview = addon_module("addon.surfaces.preview")
    offscreen = addon_module("gpu_shaders.offscreen")
    camera = addon_module("kernels.common.camera")
    meshes = len(bpy.data.meshes)
    assert bpy.ops.tessera.parametric_surface_add(surface="TREFOIL", factor=20, output="LIVE") == {"FINISHED"}
    live = bpy.context.active_object
    assert live.type == "EMPTY" and live.tessera.surface.is_surface and len(bpy.data.meshes) == meshes
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=1, radius=4.0, location=(0.5, 0.0, 0.0))
    points_ob = bpy.context.active_object
    live.tessera.surface.instance_object = points_ob
    live.location = (0.0, 0.0, 1.0)
    bpy.context.view_layer.update()
    cam = camera.Camera(camera.look_at_view((4, -16, 7), (0, 0, 0)), camera.perspective(0.9, 1.0, 0.1, 100), 200, 200)
    model = np.array(live.matrix_world)
    entry = preview.entry_for(live, camera.Camera(cam.view @ model, cam.projection, 200, 200))
    assert entry.draw.triangle_count == 12 * 2 * 20 * 20  # fixed factor, one instance per vertex
    gpu = offscreen.render(lambda: entry.draw.draw(cam.projection @ cam.view @ model, color=(1, 1, 1, 1), lit=False),
                           size=(200, 200))
    bpy.context.view_layer.objects.active = live
    assert bpy.ops.tessera.parametric_surface_bake() == {"FINISHED"}
    baked = bpy.context.active_object
    pos = np.array([v.co for v in baked.data.vertices], np.float32)
    tris = np.array([p.vertices[:] for p in baked.data.polygons], np.int32)
    cpu = offscreen.render_triangles(pos, tris, cam.projection @ cam.view @ np.array(baked.matrix_world),
                                     size=(200, 200), color=(1, 1, 1, 1), lit=False)
    a, b = cpu[..., 0] > 127, gpu[..., 0] > 127
    assert a.sum() > 1500 and np.mean(a == b) >= 0.998
    # moving the control mesh moves the surfaces (the preview rebuilds its points)
    before = entry.source[0].copy()
    points_ob.location.x += 1.0
    bpy.context.view_layer.update()
    moved = preview.entry_for(live, camera.Camera(cam.view @ model, cam.projection, 200, 200))
    assert np.allclose(moved.source[0] - before, [1.0, 0.0, 0.0], atol=1e-6)
    # factors from the camera: near instances finer than far ones
    live.tessera.surface.factor_mode = "CAMERA"
    far = preview.instance_factors(live, preview.control_points(live),
                                   camera.Camera(cam.view @ model, cam.projection, 200, 200))
    assert len(np.unique(far)) > 1

"""The GPU path for PN / Phong / linear tessellation (tier: gpu; llvmpipe in CI): the instanced-pattern preview
against the CPU-applied mesh, the crack test, the compute apply against numpy, and the displacement hook."""

import numpy as np
import pytest

pytestmark = [pytest.mark.blender, pytest.mark.gpu]


@pytest.fixture
def suzanne(bpy_module, addon_module, clean_scene):
    bpy_module.ops.mesh.primitive_monkey_add()
    ob = bpy_module.context.active_object
    for poly in ob.data.polygons:
        poly.use_smooth = True
    arrays, _ = addon_module("addon.bridge").read_mesh(ob.data)
    return arrays


def _levels(addon_module, arrays, mode, cam=None):
    tess = addon_module("kernels.tessellation.tessellate")
    if mode == "UNIFORM":
        return tess.uniform_levels(arrays, 4), None, "EQUAL"
    adaptive = addon_module("kernels.tessellation.adaptive")
    settings = adaptive.AdaptiveSettings(metrics=("PROJECTED", "SILHOUETTE"), max_level=12, edge_pixels=6.0)
    edge, inner = adaptive.adaptive_levels(arrays.positions.astype(np.float64), arrays.triangles, settings, cam)
    return edge, inner, "FRACTIONAL_EVEN"


def _cameras(Camera, rng, n, size=200):
    for _ in range(n):
        d = rng.normal(size=3)
        eye = rng.uniform(3.0, 6.0) * d / np.linalg.norm(d)
        yield Camera.looking_at(eye, rng.normal(scale=0.2, size=3), fov_deg=40, width=size, height=size, far=100)


@pytest.mark.parametrize("method", ["PN", "PHONG"])
@pytest.mark.parametrize("mode", ["UNIFORM", "ADAPTIVE"])
def test_preview_renders_like_the_applied_mesh(gpu_renderer, addon_module, suzanne, method, mode):
    tess = addon_module("kernels.tessellation.tessellate")
    preview = addon_module("gpu_shaders.tessellation.draw")
    render = addon_module("gpu_shaders.offscreen").render_triangles
    Camera = addon_module("kernels.common.camera").Camera
    options = tess.SurfaceOptions()
    for cam in _cameras(Camera, np.random.default_rng(3), 3):
        edge, inner, spacing = _levels(addon_module, suzanne, mode, cam)
        out = tess.tessellate(suzanne, edge, inner, spacing, method, backend="numpy", options=options).mesh
        inputs = tess.surface_inputs(suzanne, edge, method, options)
        data = preview.PatchDrawData(inputs, method, options.alpha)
        data.set_levels(inputs.edge_levels, inner, spacing)
        assert data.triangle_count == len(out.triangles)
        vp = cam.projection @ cam.view
        normals = out.corner_normals if out.corner_normals is not None else out.point_normals
        cpu = render(out.positions, out.triangles, vp, size=(200, 200), normals=normals)
        gpu = addon_module("gpu_shaders.offscreen").render(lambda vp=vp, d=data: d.draw(vp), size=(200, 200))
        assert (cpu[..., 0] > 0).sum() > 3000
        close = np.all(np.abs(cpu.astype(int) - gpu.astype(int)) <= 2, axis=-1)
        assert close.mean() >= 0.995, close.mean()


def test_compute_apply_equals_numpy(gpu_renderer, addon_module, suzanne):
    tess = addon_module("kernels.tessellation.tessellate")
    preview = addon_module("gpu_shaders.tessellation.draw")
    Camera = addon_module("kernels.common.camera").Camera
    cam = next(_cameras(Camera, np.random.default_rng(1), 1))
    for method, mode in (("PN", "UNIFORM"), ("PN", "ADAPTIVE"), ("PHONG", "ADAPTIVE"), ("PHONG", "UNIFORM")):
        edge, inner, spacing = _levels(addon_module, suzanne, mode, cam)
        options = tess.SurfaceOptions(alpha=0.6)
        want = tess.tessellate(suzanne, edge, inner, spacing, method, backend="numpy", options=options)
        got = tess.tessellate(suzanne, edge, inner, spacing, method, backend="numpy", options=options,
                              surface=lambda ref, inputs, m=method: preview.evaluate_on_gpu(ref, inputs, m, 0.6))
        assert np.array_equal(got.mesh.triangles, want.mesh.triangles)
        scale = np.abs(want.mesh.positions).max()
        assert np.abs(got.mesh.positions - want.mesh.positions).max() <= 1e-5 * scale, method
        assert np.abs(got.mesh.point_normals - want.mesh.point_normals).max() <= 1e-5, method


def _sharp_cube(MeshArrays):
    """A closed cube whose every edge is sharp: corner normals are the face normals."""
    v = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], np.float32)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))], np.int32)
    n = np.cross(v[tris[:, 1]] - v[tris[:, 0]], v[tris[:, 2]] - v[tris[:, 0]])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return MeshArrays(positions=v, triangles=tris, corner_normals=np.repeat(n[:, None], 3, axis=1))


def test_adaptive_pn_preview_has_no_cracks(gpu_renderer, addon_module):
    """A closed mesh (a torus with random vertex order; a cube with sharp edges, watertight mode), PN with
    adaptive fractional levels, flat white on black from 20 random cameras: no black pixel where the welded CPU
    mesh covers the view (eroded by one pixel, so outline rasterisation does not count)."""
    from tessera.tools.generators import random_closed

    tess = addon_module("kernels.tessellation.tessellate")
    adaptive = addon_module("kernels.tessellation.adaptive")
    preview = addon_module("gpu_shaders.tessellation.draw")
    offscreen = addon_module("gpu_shaders.offscreen")
    MeshArrays = addon_module("kernels.common.mesh_arrays").MeshArrays
    Camera = addon_module("kernels.common.camera").Camera
    positions, triangles = random_closed(4, 10, 6)
    meshes = [MeshArrays(positions=positions * 1.5, triangles=triangles), _sharp_cube(MeshArrays)]
    settings = adaptive.AdaptiveSettings(metrics=("PROJECTED", "SILHOUETTE"), max_level=16, edge_pixels=8.0)
    rng = np.random.default_rng(11)
    for i, cam in enumerate(_cameras(Camera, rng, 20, size=160)):
        mesh = meshes[i % 2]
        edge, inner = adaptive.adaptive_levels(mesh.positions.astype(np.float64), mesh.triangles, settings, cam,
                                               mesh.corner_normals)
        inputs = tess.surface_inputs(mesh, edge, "PN", tess.SurfaceOptions())
        data = preview.PatchDrawData(inputs, "PN")
        data.set_levels(inputs.edge_levels, inner, "FRACTIONAL_EVEN")
        vp = cam.projection @ cam.view
        img = offscreen.render(lambda vp=vp, d=data: d.draw(vp, color=(1, 1, 1, 1), lit=False), size=(160, 160))
        out = tess.tessellate(mesh, edge, inner, "FRACTIONAL_EVEN", "PN", backend="numpy").mesh
        ref = offscreen.render_triangles(out.positions, out.triangles, vp, size=(160, 160), color=(1, 1, 1, 1),
                                         lit=False)[..., 0] > 127
        p = np.pad(ref, 1, mode="edge")
        inside = p[1:-1, 1:-1] & p[:-2, 1:-1] & p[2:, 1:-1] & p[1:-1, :-2] & p[1:-1, 2:]
        assert inside.sum() > 1500
        assert not (inside & (img[..., 0] <= 127)).any(), int((inside & (img[..., 0] <= 127)).sum())


@pytest.mark.parametrize("mode", ["HEIGHT", "VECTOR", "TANGENT"])
def test_displacement_hook_moves_the_preview_like_the_cpu(gpu_renderer, addon_module, suzanne, mode):
    """A smooth map sampled at the UVs in the vertex shader displaces the preview as the same map applied to the
    CPU mesh per corner ((value - mid) * strength along the shading normal, as an object-space vector, or in the
    tangent frame of corner tangents interpolated like the UVs), pixel for pixel; and it is shaded with the displaced
    surface's normals, nearer to the displaced mesh's own normals than to the undisplaced ones."""
    import gpu

    tess = addon_module("kernels.tessellation.tessellate")
    ts = addon_module("kernels.displacement.tangent_space")
    shared_vertex_normals = addon_module("kernels.common.normals").shared_vertex_normals
    preview = addon_module("gpu_shaders.tessellation.draw")
    offscreen = addon_module("gpu_shaders.offscreen")
    Camera = addon_module("kernels.common.camera").Camera
    size = 256
    v, u = np.mgrid[0:size, 0:size] / size
    image = np.zeros((size, size, 4), np.float32)
    image[..., 0] = 0.5 + 0.4 * np.sin(6 * u) * np.cos(5 * v)
    image[..., 1] = 0.5 + 0.3 * np.cos(4 * u + 1)
    image[..., 2] = 0.5 + 0.3 * np.sin(3 * v)
    image[..., 3] = 1.0
    texture = gpu.types.GPUTexture((size, size), format="RGBA32F", data=gpu.types.Buffer("FLOAT", image.size,
                                                                                           image.ravel()))
    levels = tess.uniform_levels(suzanne, 4)
    uvs = suzanne.corner_attributes["UVMap"]
    tangents = ts.triangle_tangents(suzanne.positions[suzanne.triangles], uvs)
    suzanne.corner_attributes["tangent"] = tangents
    out = tess.tessellate(suzanne, levels, method="PN", backend="numpy").mesh
    inputs = tess.surface_inputs(suzanne, levels, "PN", tess.SurfaceOptions())
    data = preview.PatchDrawData(inputs, "PN", uvs=uvs, tangents=tangents)
    data.set_levels(inputs.edge_levels)
    disp = preview.Displacement(texture, mode, mid_level=0.5, strength=0.3)
    corners = out.positions[out.triangles].astype(np.float64)  # (M, 3, 3), per corner: UV seams stay apart
    normals = out.corner_normals if out.corner_normals is not None else out.point_normals[out.triangles]
    value = ts.sample_linear(image, out.corner_attributes["UVMap"])[..., :3]
    if mode == "HEIGHT":
        moved = corners + normals * ((value.mean(axis=-1) - 0.5) * 0.3)[..., None]
    elif mode == "VECTOR":
        moved = corners + (value - 0.5) * 0.3
    else:
        tg = out.corner_attributes["tangent"].reshape(-1, 4)
        moved = corners + ts.tangent_offsets(value.reshape(-1, 3), normals.reshape(-1, 3), tg[:, :3],
                                             np.where(tg[:, 3] < 0, -1.0, 1.0), 0.5, 0.3).reshape(corners.shape)
    flat = np.arange(moved.size // 3).reshape(-1, 3)
    # the displaced mesh's own normals: its corners welded back to their vertices (UV seams averaged)
    welded = np.zeros((len(out.positions), 3))
    np.add.at(welded, out.triangles.ravel(), moved.reshape(-1, 3))
    welded /= np.maximum(np.bincount(out.triangles.ravel(), minlength=len(welded)), 1)[:, None]
    displaced_normals = shared_vertex_normals(welded, out.triangles)[out.triangles]
    white = {"color": (1.0, 1.0, 1.0, 1.0), "lit": False}
    changed, nearer = 0.0, []
    for cam in _cameras(Camera, np.random.default_rng(8), 3):
        vp = cam.projection @ cam.view
        cpu = offscreen.render_triangles(moved.reshape(-1, 3), flat, vp, size=(200, 200), **white)
        gpu_flat = offscreen.render(lambda vp=vp: data.draw(vp, displacement=disp, **white), size=(200, 200))
        close = np.all(np.abs(cpu.astype(int) - gpu_flat.astype(int)) <= 2, axis=-1)
        assert close.mean() >= 0.995, close.mean()
        gpu_img = offscreen.render(lambda vp=vp: data.draw(vp, displacement=disp), size=(200, 200))
        plain = offscreen.render(lambda vp=vp: data.draw(vp), size=(200, 200))
        changed += np.mean(np.any(plain != gpu_img, axis=-1))
        covered = cpu[..., 0] > 127

        def error(normals, vp=vp, covered=covered, gpu_img=gpu_img):
            ref = offscreen.render_triangles(moved.reshape(-1, 3), flat, vp, size=(200, 200), normals=normals)
            return float(np.abs(ref[covered, :3].astype(int) - gpu_img[covered, :3].astype(int)).mean())

        nearer.append((error(displaced_normals), error(normals)))
    assert changed / 3 > 0.02  # the map visibly moved the surface
    assert all(d < u for d, u in nearer), nearer

"""A nailboard on the GPU (tier: gpu): the dependent lookup through the offset map gives the CPU pre-warped image
bit for bit, and per-texel depth makes a relief sphere intersect a GPU-drawn plane where the real sphere does."""

import numpy as np
import pytest

pytestmark = [pytest.mark.blender, pytest.mark.gpu]


def test_nearest_lookup_is_the_cpu_prewarp_bit_for_bit(gpu_renderer, addon_module):
    pw = addon_module("kernels.impostors.prewarp")
    board = addon_module("gpu_shaders.impostors.draw")
    offscreen = addon_module("gpu_shaders.offscreen")
    rng = np.random.default_rng(0)
    w, h = 96, 64
    d = rng.uniform(0, 3, (h, w))
    colours = np.ones((h, w, 4), np.float32)
    colours[..., :3] = rng.integers(0, 256, (h, w, 3)) / 255.0  # 8-bit exact, as the offscreen reads back
    frame = pw.ReliefFrame(np.zeros(3), np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0, 0, 1.0]))
    splat = pw.forward_splat(d, frame, np.array([30.0, 20.0, 40.0]))
    assert 0 < splat.hole_fraction < 0.5
    data = board.BoardDrawData(frame, colours, d, splat)
    # one board texel on one pixel: x, y scaled onto clip space, z kept inside it
    vp = np.array([[2 / w, 0, 0, -1], [0, 2 / h, 0, -1], [0, 0, -0.01, 0], [0, 0, 0, 1]], np.float64)
    gpu = offscreen.render(lambda: data.draw(vp), size=(w, h), background=(0, 0, 0, 1))
    cpu = np.round(splat.gather(colours) * 255).astype(np.uint8)
    cpu[splat.source < 0] = (0, 0, 0, 255)
    assert np.array_equal(gpu, cpu)


def sphere_relief(n, radius):
    """A hemisphere of ``radius`` over an n x n board of side 2 radius centred at the origin: displacement (n, n) and
    present (n, n) bool (where the sphere is)."""
    c = (np.arange(n) + 0.5) / n * 2 * radius - radius
    x, y = np.meshgrid(c, c)
    r2 = x * x + y * y
    present = r2 < radius * radius
    d = np.sqrt(np.maximum(radius * radius - r2, 0.0))
    return d, present


def test_a_relief_sphere_meets_a_gpu_plane_where_the_real_sphere_does(gpu_renderer, addon_module):
    pw = addon_module("kernels.impostors.prewarp")
    board = addon_module("gpu_shaders.impostors.draw")
    offscreen = addon_module("gpu_shaders.offscreen")
    camera = addon_module("kernels.common.camera")
    n, radius = 384, 1.0
    d, present = sphere_relief(n, radius)
    s = 2 * radius / n
    frame = pw.ReliefFrame(np.array([-radius, -radius, 0.0]), np.array([s, 0, 0]), np.array([0, s, 0]),
                           np.array([0, 0, 1.0]))
    eye = np.array([0.4, -1.2, 6.0])
    splat = pw.fill_holes(pw.forward_splat(d, frame, eye, present), max_gap=4)  # inside the outline only
    red = np.zeros((n, n, 4), np.float32)
    red[..., 0], red[..., 3] = 1.0, 1.0
    data = board.BoardDrawData(frame, red, d, splat)
    cam = camera.Camera(camera.look_at_view(eye, (0, 0, 0.3)), camera.perspective(0.55, 1.0, 0.5, 50.0), 200, 200)
    vp = cam.projection @ cam.view
    # a plane through the sphere: z = 0.6 y + 0.55, green, drawn as two triangles: it cuts the visible cap
    quad = np.array([[-3, -3, 0.6 * -3 + 0.55], [3, -3, 0.6 * -3 + 0.55], [3, 3, 0.6 * 3 + 0.55],
                     [-3, 3, 0.6 * 3 + 0.55]], np.float32)
    quad_tris = np.array([[0, 1, 2], [0, 2, 3]], np.int32)
    # ground truth: a fine sphere mesh and the plane
    uu, vv = np.meshgrid(np.linspace(0, np.pi, 200), np.linspace(0, 2 * np.pi, 400), indexing="ij")
    sph = np.stack([np.sin(uu) * np.cos(vv), np.sin(uu) * np.sin(vv), np.cos(uu)], -1).reshape(-1, 3) * radius
    i, j = np.meshgrid(np.arange(199), np.arange(399), indexing="ij")
    a = (i * 400 + j).ravel()
    sph_tris = np.concatenate([np.stack([a, a + 400, a + 401], 1), np.stack([a, a + 401, a + 1], 1)]).astype(np.int32)

    def truth():
        offscreen.draw_triangles(sph.astype(np.float32), sph_tris, vp, (1, 0, 0, 1), False)
        offscreen.draw_triangles(quad, quad_tris, vp, (0, 1, 0, 1), False)

    def boarded():
        offscreen.draw_triangles(quad, quad_tris, vp, (0, 1, 0, 1), False)
        data.draw(vp)

    want = offscreen.render(truth, size=(200, 200))
    got = offscreen.render(boarded, size=(200, 200))
    alone = offscreen.render(lambda: offscreen.draw_triangles(sph.astype(np.float32), sph_tris, vp, (1, 0, 0, 1),
                                                              False), size=(200, 200))[..., 0] > 127
    sphere_want, sphere_got = want[..., 0] > 127, got[..., 0] > 127
    assert sphere_want.sum() > 2000 and (alone & ~sphere_want).sum() > 1000  # the plane hides part of the sphere
    diff = sphere_want != sphere_got
    # every pixel that differs lies within 1 px of the true picture's sphere boundary (silhouette or the intersection)
    pad = np.pad(sphere_want, 1, mode="edge")
    windows = np.stack([pad[1 + dy:201 + dy, 1 + dx:201 + dx] for dy in (-1, 0, 1) for dx in (-1, 0, 1)])
    boundary = windows.any(axis=0) & ~windows.all(axis=0)
    assert not (diff & ~boundary).any(), int((diff & ~boundary).sum())
    assert diff.sum() < 0.05 * boundary.sum() + 40


def test_a_board_from_the_cycles_worker_stands_in_for_the_object(clean_scene, gpu_renderer, bpy_module, addon_module):
    """The whole chain: the worker renders a sphere's board with Cycles, the CPU pre-warps it for the eye, the GPU
    draws it with per-texel depth next to a plane through the sphere; the picture is the sphere mesh's and the plane's
    within 1 px of their outline and intersection."""
    bpy = bpy_module
    pw = addon_module("kernels.impostors.prewarp")
    board = addon_module("gpu_shaders.impostors.draw")
    offscreen = addon_module("gpu_shaders.offscreen")
    camera = addon_module("kernels.common.camera")
    worker = addon_module("addon.impostors.worker")
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=1.0)
    ball = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    eye = np.array([0.6, -5.5, 2.5])
    images = worker.request_board(ball, eye, res_screen=200, fov=0.55, samples=1).result(timeout=240)
    frame = images.setup.frame
    splat = pw.fill_holes(pw.forward_splat(images.displacement, frame, eye, images.present), max_gap=4)
    red = np.zeros(images.colours.shape, np.float32)
    red[..., 0], red[..., 3] = 1.0, 1.0
    data = board.BoardDrawData(frame, red, images.displacement, splat, images.normals)
    cam = camera.Camera(camera.look_at_view(eye, (0, 0, 0)), camera.perspective(0.55, 1.0, 0.5, 50.0), 200, 200)
    vp = cam.projection @ cam.view
    me = ball.data
    pos = np.array([v.co for v in me.vertices], np.float32)
    me.calc_loop_triangles()
    tris = np.array([t.vertices[:] for t in me.loop_triangles], np.int32)
    quad = np.array([[-3, -3, -0.8], [3, -3, -0.8], [3, 3, 1.6], [-3, 3, 1.6]], np.float32)  # z = 0.4 y + 0.4
    quad_tris = np.array([[0, 1, 2], [0, 2, 3]], np.int32)
    want = offscreen.render(lambda: (offscreen.draw_triangles(pos, tris, vp, (1, 0, 0, 1), False),
                                     offscreen.draw_triangles(quad, quad_tris, vp, (0, 1, 0, 1), False)),
                            size=(200, 200))
    got = offscreen.render(lambda: (offscreen.draw_triangles(quad, quad_tris, vp, (0, 1, 0, 1), False), data.draw(vp)),
                           size=(200, 200))
    alone = offscreen.render(lambda: offscreen.draw_triangles(pos, tris, vp, (1, 0, 0, 1), False), size=(200, 200))
    sphere_want, sphere_got = want[..., 0] > 127, got[..., 0] > 127
    assert sphere_want.sum() > 1500 and ((alone[..., 0] > 127) & ~sphere_want).sum() > 500
    pad = np.pad(sphere_want, 1, mode="edge")
    windows = np.stack([pad[1 + dy:201 + dy, 1 + dx:201 + dx] for dy in (-1, 0, 1) for dx in (-1, 0, 1)])
    boundary = windows.any(axis=0) & ~windows.all(axis=0)
    diff = sphere_want != sphere_got
    assert not (diff & ~boundary).any(), int((diff & ~boundary).sum())


def test_the_viewport_draws_a_live_nailboard_without_waiting(clean_scene, gpu_renderer, bpy_module, addon_module):
    """The viewport side: the first frame asks for a board (queued for a timer, nothing drawn, nothing waited for);
    once the worker is done and the board pre-warped, the next frames upload it a step each (its shader, then each
    texture: no frame holds them all) and then draw the object from it, pre-warped for that frame's eye."""
    import time
    from types import SimpleNamespace

    bpy = bpy_module
    preview = addon_module("addon.impostors.preview")
    offscreen = addon_module("gpu_shaders.offscreen")
    camera = addon_module("kernels.common.camera")
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0)
    ball = bpy.context.active_object
    mat = bpy.data.materials.new("Red")
    addon_module("addon.compat").use_material_nodes(mat)
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (1, 0, 0, 1)
    ball.data.materials.append(mat)
    ball.tessera.nailboard.enabled = True
    ball.tessera.nailboard.samples = 1
    eye = np.array([0.5, -6.0, 2.0])
    cam = camera.Camera(camera.look_at_view(eye, (0, 0, 0)), camera.perspective(0.6, 1.0, 0.5, 50.0), 160, 160)
    context = SimpleNamespace(view_layer=bpy.context.view_layer, space_data=None)  # no 3D view: every visible object
    region = SimpleNamespace(height=160, width=160)
    t = time.perf_counter()
    first = offscreen.render(lambda: preview._draw(context, region, cam.view, cam.projection), size=(160, 160))
    assert time.perf_counter() - t < 2.0 and first[..., :3].max() == 0  # asked, not waited for: nothing yet
    assert len(preview._queue) == 1
    preview._start_queued()  # what the timer does outside the draw callback
    live = preview.MANAGER.boards[ball.session_uid]
    live.pending.job.result(timeout=240)
    draw = lambda: preview._draw(context, region, cam.view, cam.projection)  # noqa: E731
    swapped = offscreen.render(draw, size=(160, 160))  # the board swapped in; its pre-warp asked of a worker thread
    assert live.images is not None and live.pending is None
    assert swapped[..., :3].max() == 0 and preview.PREWARP_COUNT[0] >= 1
    preview._prewarps[ball.session_uid].pending[2].result(timeout=60)
    frames = 0
    while not preview.board_drawn(ball) and frames < 10:
        offscreen.render(draw, size=(160, 160))
        frames += 1
    assert preview.board_drawn(ball) and frames == 5  # its shader, colours, depths, normals; then offsets and drawn
    second = offscreen.render(draw, size=(160, 160))
    count = preview.PREWARP_COUNT[0]
    again = offscreen.render(draw, size=(160, 160))
    assert preview.PREWARP_COUNT[0] == count and np.array_equal(again, second)  # the same view: no new pre-warp
    drawn = second[..., :3].max(axis=-1) > 10
    assert drawn.sum() > 1000 and (second[..., 0][drawn] >= second[..., 2][drawn]).all()
    preview.MANAGER.boards.clear()

"""The nailboard worker (tier: blender): a separate Blender process renders a sphere alone with Cycles through the
board's orthographic camera; the depth pass gives the sphere's displacements over the board, the alpha where it is,
and the viewport side did not wait for it."""

import os
import threading
import time

import numpy as np
import pytest

pytestmark = pytest.mark.blender


def test_the_worker_renders_a_sphere_board(clean_scene, bpy_module, addon_module, tmp_path):
    bpy = bpy_module
    worker = addon_module("addon.impostors.worker")
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=1.0, location=(0.5, 0.2, 0.1))
    ball = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    holder = bpy.data.objects.new("Holder", None)  # a parent with a transform: the worker places the ball unparented
    bpy.context.scene.collection.objects.link(holder)
    holder.location = (3.0, -1.0, 2.0)
    bpy.context.view_layer.update()
    ball.parent = holder  # the ball's world centre is now (3.5, -0.8, 2.1), its local one still (0.5, 0.2, 0.1)
    bpy.ops.mesh.primitive_cube_add(location=(4, 4, 4))  # another object: left out of the board and of its file
    lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "POINT"))  # lights the board: written
    bpy.context.scene.collection.objects.link(lamp)
    off = bpy.data.collections.new("Off")  # a collection excluded from the view layer: its light is not
    bpy.context.scene.collection.children.link(off)
    off.objects.link(bpy.data.objects.new("OffLamp", bpy.data.lights.new("OffLamp", "POINT")))
    bpy.context.view_layer.layer_collection.children["Off"].exclude = True
    bpy.context.view_layer.update()
    eye = np.array([0.5, -7.0, 2.0])
    t = time.perf_counter()
    job = worker.request_board(ball, eye, res_screen=400, fov=np.radians(40), samples=2)
    started = time.perf_counter() - t
    assert not job.done() or started < 5  # the request returns without rendering
    if hasattr(os, "getpriority") and job.process.poll() is None:  # below the viewport's priority
        try:
            assert os.getpriority(os.PRIO_PROCESS, job.process.pid) >= 10
        except ProcessLookupError:  # it finished in between
            pass
    with bpy.data.libraries.load(os.path.join(job.folder, "scene.blend")) as (written, _):
        assert ball.name in written.objects and "Lamp" in written.objects and not written.scenes
        assert "Cube" not in written.objects and "OffLamp" not in written.objects
    board = job.result(timeout=240)
    setup = board.setup
    n = setup.resolution
    assert board.colours.shape == (n, n, 4) and 40 <= n <= 400
    # where the sphere is: a disc of its radius in the middle of the board
    c = (np.arange(n) + 0.5) / n * setup.size - setup.size / 2
    x, y = np.meshgrid(c, c)
    disc = x * x + y * y < 0.97 ** 2
    ring = x * x + y * y > 1.03 ** 2
    assert board.present[disc].all() and not board.present[ring].any()
    # the depth pass: the front of the sphere, d = size / 2 + sqrt(1 - x^2 - y^2) over the board's back plane
    want = setup.size / 2 + np.sqrt(np.maximum(1 - x * x - y * y, 0))
    inner = x * x + y * y < 0.9 ** 2
    assert np.abs(board.displacement[inner] - want[inner]).max() < 0.02
    # the normals face the eye's side
    f = setup.frame.f
    assert (board.normals[inner] @ f > 0.3).all()


def test_the_images_are_read_off_the_main_thread(clean_scene, bpy_module, addon_module, monkeypatch):
    """Once the render has finished, `BoardJob.done()` has the images read on a worker thread: the viewport's draw
    callback, which swaps the board in, never reads a file."""
    bpy = bpy_module
    worker = addon_module("addon.impostors.worker")
    readers = []
    real = worker.read_channels

    def recording(*args):
        readers.append(threading.current_thread() is threading.main_thread())
        return real(*args)

    monkeypatch.setattr(worker, "read_channels", recording)
    bpy.ops.mesh.primitive_ico_sphere_add(radius=0.5)
    ball = bpy.context.active_object
    job = worker.request_board(ball, np.array([0.0, -5.0, 0.0]), res_screen=100, fov=np.radians(40), samples=1)
    job.process.wait(timeout=240)
    deadline = time.monotonic() + 60
    while not job.done() and time.monotonic() < deadline:
        time.sleep(0.01)
    board = job.result()
    assert readers == [False]
    assert board.present.any()


def test_a_progressive_board_writes_its_preview_first(clean_scene, bpy_module, addon_module):
    """From `PROGRESSIVE_MIN_SAMPLES` samples the worker renders a quick preview of the same board first: the same
    outline and depth as the full render (only the colours are noisier)."""
    bpy = bpy_module
    worker = addon_module("addon.impostors.worker")
    bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16, radius=0.8)
    ball = bpy.context.active_object
    job = worker.request_board(ball, np.array([0.0, -5.0, 1.0]), res_screen=120, fov=np.radians(40),
                               samples=worker.PROGRESSIVE_MIN_SAMPLES)
    deadline = time.monotonic() + 240
    while job.preview() is None and time.monotonic() < deadline:  # read on a worker thread, started by poll()
        job.poll()
        time.sleep(0.01)
    early = job.preview()
    final = job.result(timeout=240)  # the folder goes once the final images are read: the preview was read first
    assert early is not None and not os.path.exists(job.folder)
    assert early.setup is final.setup and early.colours.shape == final.colours.shape
    inside = final.present & early.present
    assert inside.sum() >= 0.97 * max(final.present.sum(), early.present.sum()) > 0
    assert np.abs(early.displacement[inside] - final.displacement[inside]).max() < 0.02
    few = worker.request_board(ball, np.array([0.0, -5.0, 1.0]), res_screen=120, fov=np.radians(40), samples=1)
    few.result(timeout=240)
    few.poll()
    assert few.preview() is None  # one sample: nothing to preview


def _shrunk(mask, steps):
    """``mask`` (H, W) bool less ``steps`` texels along its outline (4-neighbour erosion)."""
    for _ in range(steps):
        pad = np.pad(mask, 1)
        mask = pad[1:-1, 1:-1] & pad[:-2, 1:-1] & pad[2:, 1:-1] & pad[1:-1, :-2] & pad[1:-1, 2:]
    return mask


def _grown(mask, steps):
    """``mask`` (H, W) bool plus ``steps`` texels around its outline (4-neighbour dilation)."""
    return ~_shrunk(~mask, steps)


def test_a_monkey_board_prewarped_for_a_moved_eye_has_no_holes_inside_its_outline(clean_scene, bpy_module,
                                                                                   addon_module):
    """A real Cycles board of a smooth Suzanne (ears in front of the head, edge texels whose one depth sample hit the
    background), pre-warped as the viewport does it for the board's own eye and for eyes moved a little sideways and
    up: the splat alone opens thousands of gaps (texels in front of the board's plane spread apart), and
    `fill_holes` with the preview's gap closes every one inside the object's outline (the depth-buffered splat's,
    small gaps closed, two texels in), so nothing of the viewport shows through the object."""
    bpy = bpy_module
    worker, pw = addon_module("addon.impostors.worker"), addon_module("kernels.impostors.prewarp")
    gap = addon_module("addon.impostors.preview").HOLE_GAP
    bpy.ops.mesh.primitive_monkey_add()
    monkey = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    eye = np.array([4.5, -5.0, 3.5])
    board = worker.request_board(monkey, eye, res_screen=500, fov=np.radians(40), samples=2).result(timeout=240)
    assert board.present.sum() > 10000
    for moved in ([0.0, 0.0, 0.0], [0.4, 0.0, 0.0], [0.0, 0.3, 0.4]):
        target = eye + np.array(moved)
        splat = pw.forward_splat(board.displacement, board.setup.frame, target, board.present)
        drawn = pw.fill_holes(splat, gap)
        oracle = pw.zbuffer_splat(board.displacement, board.setup.frame, target, board.present)
        inside = _shrunk(_grown(oracle.source >= 0, 3), 5)  # its outline, small gaps closed, two texels in
        holes = (drawn.source < 0) & inside
        raw = (splat.source < 0) & inside
        assert raw.sum() > 1000 and holes.sum() == 0, (moved, int(raw.sum()), int(holes.sum()))  # the fill closes all

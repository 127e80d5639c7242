"""When a live nailboard asks for a new board ([Clua et al., §5 and §5.1]), on scripted camera
paths (tier: blender): a static camera never; a dolly-in from the approach and resolution tests only; a strafe from
parallax; an object move at once; a return to an earlier viewpoint from the cache; prediction asks ahead. The
renderer here finishes at once (the real one, a separate process, is tested in test_blender_worker.py)."""

import time

import numpy as np
import pytest

pytestmark = pytest.mark.blender

FOV, RES = np.radians(50), 800


class InstantJob:
    def __init__(self, setup):
        self.setup = setup

    def done(self):
        return True

    def result(self):
        return self.setup

    def cancel(self):
        pass


def manager(addon_module, **kw):
    live = addon_module("addon.impostors.live")
    board = addon_module("kernels.impostors.board")
    asked = []

    def request(ob, eye, res_screen, fov):
        from mathutils import Vector

        corners = np.array([ob.matrix_world @ Vector(c) for c in ob.bound_box])
        asked.append(np.array(eye))
        return InstantJob(board.board_setup(corners.min(0), corners.max(0), eye, res_screen, fov))

    return live.NailboardManager(request, **kw), asked


def run(m, ob, eyes):
    for eye in eyes:
        m.update(ob, eye, RES, FOV)


def test_static_camera_then_dolly_then_strafe(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    bpy.ops.mesh.primitive_cube_add()
    ob = bpy.context.active_object
    m, _ = manager(addon_module)
    run(m, ob, [np.array([0.0, -12.0, 0.0])] * 30)
    assert m.regenerations == 1 and m.reasons == []  # the first board, then nothing
    run(m, ob, [np.array([0.0, y, 0.0]) for y in np.linspace(-12, -4, 40)])  # dolly in
    assert m.regenerations > 1
    assert all(not r.parallax and (r.approach or r.resolution) for r in m.reasons)
    before = m.regenerations
    m.reasons.clear()
    run(m, ob, [np.array([x, -4.0, 0.0]) for x in np.linspace(0, 3, 40)])  # strafe
    assert m.regenerations > before and m.reasons[0].parallax


def test_object_move_is_immediate_and_the_cache_serves_a_return(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    bpy.ops.mesh.primitive_cube_add()
    ob = bpy.context.active_object
    m, asked = manager(addon_module)
    a, b = np.array([0.0, -12.0, 0.0]), np.array([9.0, -8.0, 0.0])
    run(m, ob, [a, a, b, b])
    assert m.regenerations == 2
    run(m, ob, [a])  # back where the first board was made: from the cache, no render
    assert m.regenerations == 2 and m.cache_hits == 1
    ob.location.x += 0.5
    bpy.context.view_layer.update()
    run(m, ob, [a])
    assert m.regenerations == 3  # moved: at once, even with the camera still


def test_prediction_asks_for_the_eye_ahead(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    bpy.ops.mesh.primitive_cube_add()
    ob = bpy.context.active_object
    m, asked = manager(addon_module, lead=5)
    eyes = [np.array([0.0, -12.0 + 0.2 * k, 0.0]) for k in range(3)]
    run(m, ob, eyes[:1])
    m.boards[ob.session_uid].board = None  # force a request on the next frame, with a velocity known
    run(m, ob, eyes[1:2])
    assert np.allclose(asked[-1], eyes[1] + 5 * (eyes[1] - eyes[0]))


class ProgressiveJob(InstantJob):
    """A render that offers its preview after ``preview_after`` polls and finishes after ``done_after``."""

    def __init__(self, setup, preview_after=2, done_after=5):
        super().__init__(setup)
        self.polls, self.preview_after, self.done_after = 0, preview_after, done_after

    def done(self):
        self.polls += 1
        return self.polls > self.done_after

    def preview(self):
        return ("preview", self.setup) if self.polls > self.preview_after else None


def test_a_progressive_board_is_drawn_from_its_preview_until_the_full_render(clean_scene, bpy_module, addon_module):
    """Progressive delivery: while a board renders, its preview (``job.preview()``) is drawn as soon as it is there,
    with the pending board's viewpoint; the full render replaces it, and only the full render is cached."""
    bpy = bpy_module
    live_mod = addon_module("addon.impostors.live")
    board = addon_module("kernels.impostors.board")
    bpy.ops.mesh.primitive_cube_add()
    ob = bpy.context.active_object
    jobs = []

    def request(ob, eye, res_screen, fov):
        jobs.append(ProgressiveJob(board.board_setup(np.full(3, -1.0), np.full(3, 1.0), eye, res_screen, fov)))
        return jobs[-1]

    m = live_mod.NailboardManager(request)
    eye = np.array([0.0, -12.0, 0.0])
    drawn = [m.update(ob, eye, RES, FOV).images for _ in range(8)]
    job = jobs[0]
    assert len(jobs) == 1 and m.previews == 1
    assert drawn[:2] == [None, None]  # nothing yet, then the preview, then the full render
    assert ("preview", job.setup) in drawn and drawn[-1] is job.setup
    first_preview, first_final = drawn.index(("preview", job.setup)), drawn.index(job.setup)
    assert first_preview < first_final and all(d == ("preview", job.setup) for d in drawn[first_preview:first_final])
    assert [images for images, _ in m.cache.values()] == [job.setup]


EYE, NARROW, WIDE = np.array([0.0, -9.0, 2.0]), np.radians(20), np.radians(80)


def zoom_board(bpy, addon_module, resample):
    """A cube's manager (with ``resample``) whose board was made and swapped in for `EYE` at the `NARROW` field of
    view: the manager, its requests, the cube and its `LiveBoard`."""
    bpy.ops.mesh.primitive_cube_add()
    ob = bpy.context.active_object
    m, asked = manager(addon_module)
    m.resample = resample
    m.update(ob, EYE, RES, NARROW)  # asks
    return m, asked, ob, m.update(ob, EYE, RES, NARROW)  # swaps the board in


def test_a_board_much_finer_than_needed_is_resampled_and_the_full_one_serves_again(clean_scene, bpy_module,
                                                                                   addon_module):
    """Zooming out (a wider field of view from the same eye) keeps a board valid but makes it far finer than eq. 8
    asks for: it is resampled down (no render) to twice what the view needs; zooming back in, the resampled board is
    too coarse and the full one returns from the cache (no render either)."""
    live_mod = addon_module("addon.impostors.live")
    validity = addon_module("kernels.impostors.validity")
    resampled = []

    def resample(images, resolution):
        resampled.append(resolution)
        return ("resampled", resolution)

    m, asked, ob, full = zoom_board(bpy_module, addon_module, resample)
    full_res, full_images = full.board.resolution, full.images
    for fov in np.linspace(NARROW, WIDE, 30):
        live = m.update(ob, EYE, RES, fov)
    deadline = time.monotonic() + 30
    while m.resamples == 0 and time.monotonic() < deadline:  # resampled on a worker thread, swapped in when done
        live = m.update(ob, EYE, RES, WIDE)
        time.sleep(0.01)
    assert m.regenerations == 1 and m.resamples >= 1, (m.reasons, m.resamples)
    size = float(np.linalg.norm(live.board.hi - live.board.lo))
    needed = validity.sprite_resolution(RES, size, float(np.linalg.norm(EYE - live.board.centre)), WIDE)
    assert live.board.resolution < live_mod.RESAMPLE_AT * needed <= full_res
    assert live.images == ("resampled", live.board.resolution) == ("resampled", resampled[-1])
    hits = m.cache_hits
    for _ in range(3):  # zoomed back in: the resampled board is too coarse here
        live = m.update(ob, EYE, RES, NARROW)
    assert m.regenerations == 1 and m.cache_hits == hits + 1 and len(asked) == 1
    assert live.board.resolution == full_res and live.images is full_images


def test_a_failing_resample_leaves_the_board_as_rendered(clean_scene, bpy_module, addon_module):
    """A resampling that fails is tried once for that board, which is then drawn as it was rendered."""
    calls = []

    def broken(images, resolution):
        calls.append(resolution)
        raise MemoryError("simulated")

    m, _, ob, full = zoom_board(bpy_module, addon_module, broken)
    images, resolution = full.images, full.board.resolution
    deadline = time.monotonic() + 30
    while full.keep is None and time.monotonic() < deadline:
        m.update(ob, EYE, RES, WIDE)
        time.sleep(0.01)
    for _ in range(5):
        live = m.update(ob, EYE, RES, WIDE)
    assert len(calls) == 1 and m.resamples == 0 and m.regenerations == 1
    assert live.images is images and live.board.resolution == resolution

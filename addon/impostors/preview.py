"""Live nailboards in the 3D viewport: objects with ``tessera.nailboard.enabled`` are drawn from their current
board (`live.NailboardManager`), pre-warped for the eye on the CPU (8 bytes a texel uploaded) and drawn by the GPU
with per-texel depth. A pre-warp is made once per board and eye, on a worker thread, while the last one is drawn
(`splat_for`): a redraw for the same view makes none, and the main thread never makes one. The draw callback never
waits: a board is asked for through a timer (a draw callback may not save files or start processes), rendered by the
worker process, and swapped in when done. The board is drawn instead of its object (`viewport.sync_source`), hidden
with it. Nothing is drawn in background mode."""

from dataclasses import dataclass

import bpy
import numpy as np

from ...kernels.common import workers
from ...kernels.common.errors import InvalidInputError
from ...kernels.impostors.board import board_setup
from ...kernels.impostors.prewarp import fill_holes, forward_splat
from ..guarded import check_numbers
from ..viewport import Preview, outline, previewed_objects, tag_view3d_redraw
from . import worker
from .live import NailboardManager
from .settings import TOPIC

_queue = []
HOLE_GAP = 4  # texels: gaps a pre-warp may open inside an object's outline


class DeferredJob:
    """A board asked for from a draw callback: started by a timer, then the worker's `BoardJob`."""

    def __init__(self, ob, eye, res_screen, fov, samples, progressive=True):
        worker.check_renderable(ob)  # refused here (told once by the manager), not in the worker
        self.setup = board_setup(*worker.world_box(ob), eye, res_screen, fov)
        self.args, self.name, self.job = (eye, res_screen, fov, samples, progressive), ob.name, None
        _queue.append(self)
        if not bpy.app.timers.is_registered(_start_queued):
            bpy.app.timers.register(_start_queued, first_interval=0.0)

    def done(self):
        return self.job is not None and self.job.done()

    def preview(self):
        return None if self.job is None else self.job.preview()

    def poll(self):
        if self.job is not None:
            self.job.poll()

    def result(self):
        return self.job.result()

    def cancel(self):
        if self.job is not None:
            self.job.cancel()
        elif self in _queue:
            _queue.remove(self)


def _start_queued():
    while _queue:
        job = _queue.pop(0)
        ob = bpy.data.objects.get(job.name)
        if ob is not None:
            eye, res, fov, samples, progressive = job.args
            job.job = worker.request_board(ob, eye, res, fov, samples=samples, setup=job.setup,
                                           progressive=progressive)
    return None


def _poll_jobs():
    """Redraw while a board is being rendered, so it is swapped in when done; its preview and final images start
    being read here (on a worker thread, `worker.BoardJob.poll`), not in the draw callback."""
    pending = [live.pending for live in MANAGER.boards.values() if live.pending is not None]
    for job in pending:
        job.poll()
    if pending:
        tag_view3d_redraw()
        return 0.25
    return None


def _request(ob, eye, res_screen, fov):
    s = ob.tessera.nailboard
    job = DeferredJob(ob, eye, res_screen, fov, s.samples, s.progressive)
    if not bpy.app.timers.is_registered(_poll_jobs):
        bpy.app.timers.register(_poll_jobs, first_interval=0.25)
    return job


MANAGER = NailboardManager(_request, resample=worker.resample_images)


def _finite(s):
    """Whether nailboard settings ``s`` hold numbers (a script may store NaN); the panel names a bad one."""
    try:
        check_numbers(s)
    except InvalidInputError:
        return False
    return True


@dataclass
class Prewarp:
    """What the viewport draws one object from: ``shown``, the ``(images, eye, (Splat, offset rows))`` drawn now, its
    GPU ``draw`` data (`BoardDrawData`) made from ``draw_images``, and ``pending``: the ``(images, eye, future)`` of a
    pre-warp being made on a worker thread."""

    shown: tuple = None
    draw: object = None
    draw_images: object = None
    pending: tuple = None
    building: object = None  # the `BoardDrawData.steps` of a new board, one upload per redraw
    building_images: object = None


_prewarps = {}  # object session_uid -> Prewarp
PREWARP_COUNT = [0]  # pre-warps started this session (the window tier counts them per redraw)


def _prewarp(images, target):
    """The pre-warp of ``images`` for the eye ``target`` and its offset rows, ready to upload: ``(Splat, rows)``."""
    from ...gpu_shaders.impostors.draw import offset_rows

    splat = fill_holes(forward_splat(images.displacement, images.setup.frame, target, images.present), HOLE_GAP)
    return splat, offset_rows(splat)


def splat_for(ob, images, target):
    """What to draw ``ob`` from when its current board is ``images`` and the eye ``target`` (3,): ``(images, eye,
    (Splat, rows))``, or None before any is ready. For the same board and eye, the one made before (no work); for a
    new board or a moved eye, the last one made while a worker thread pre-warps the new (a timer redraws when it is
    done): the main thread never pre-warps."""
    p = _prewarps.setdefault(ob.session_uid, Prewarp())
    eye = np.asarray(target, np.float64).tobytes()
    if p.pending is not None and p.pending[2].done():
        done_images, done_eye, future = p.pending
        p.pending = None
        if future.exception() is not None:
            print(f"Tessera: a nailboard pre-warp failed: {future.exception()}")
        else:
            p.shown = (done_images, done_eye, future.result())
    if p.shown is not None and p.shown[0] is images and p.shown[1] == eye:
        return p.shown
    if p.pending is None:  # one at a time: one for an earlier eye or board is shown when done, then this one asked
        PREWARP_COUNT[0] += 1
        p.pending = (images, eye, workers.submit(_prewarp, images, np.array(target, np.float64)))
        if not bpy.app.timers.is_registered(_poll_prewarps):
            bpy.app.timers.register(_poll_prewarps, first_interval=0.02)
    return p.shown


def _poll_prewarps():
    """Redraw once a pre-warp made on a worker thread is done (the draw callback then picks it up)."""
    pending = [p.pending for p in _prewarps.values() if p.pending is not None]
    if any(future.done() for _, _, future in pending):
        tag_view3d_redraw()
    return 0.02 if pending else None


def _redraw_soon():
    """Redraw the viewports once this draw is over (a redraw asked for while drawing may be dropped)."""
    if not bpy.app.timers.is_registered(_redraw_now):
        bpy.app.timers.register(_redraw_now, first_interval=0.0)


def _redraw_now():
    tag_view3d_redraw()
    return None


def _draw(context, region, view, proj):
    from ...gpu_shaders.impostors.draw import BoardDrawData

    eye = np.linalg.inv(view)[:3, 3]
    fov = 2.0 * np.arctan(1.0 / proj[1, 1])
    for ob in previewed_objects(context, previewing):
        s = ob.tessera.nailboard
        if not _finite(s):
            continue
        MANAGER.k, MANAGER.relief_factor, MANAGER.lead = s.tolerance, 0.25 if s.relief else 1.0, s.lead
        live = MANAGER.update(ob, eye, region.height, fov)
        images = live.images
        if images is None:
            continue
        # relief mapping: pre-warped for this eye; a plain sprite: for the eye it was made for
        shown = splat_for(ob, images, eye if s.relief else live.board.eye)
        if shown is None:
            continue
        shown_images, _, (splat, rows) = shown
        p = _prewarps[ob.session_uid]
        if p.draw is None or p.draw_images is not shown_images:  # a new board: its uploads one per redraw
            if p.building is None or p.building_images is not shown_images:
                p.building = BoardDrawData.steps(shown_images.setup.frame, shown_images.colours,
                                                 shown_images.displacement, splat, shown_images.normals, rows)
                p.building_images = shown_images
            try:
                next(p.building)
                _redraw_soon()
            except StopIteration as built:
                p.draw, p.draw_images, p.building, p.building_images = built.value, shown_images, None, None
        elif p.draw.splat is not splat:
            p.draw.set_splat(splat, rows)
        if p.draw is None:  # the first board of this object is still being uploaded
            continue
        p.draw.draw(proj @ view)
        outline(context, ob, lambda mask_color, d=p.draw, vp=proj @ view: d.draw(vp, mask_color=mask_color))


def board_drawn(ob):
    """Whether ``ob``'s live board is rendered, pre-warped and uploaded, so that the viewport draws it (its uploads
    take a redraw each: the window tier waits on this before it looks)."""
    live = MANAGER.boards.get(ob.session_uid)
    p = _prewarps.get(ob.session_uid)
    return live is not None and live.images is not None and live.pending is None and p is not None \
        and p.draw is not None and p.building is None and p.draw_images is live.images


def previewing(ob):
    """The live board is on for mesh ``ob``: it is drawn instead of the object."""
    return ob.type == "MESH" and ob.tessera.nailboard.enabled


def _forget(ob):
    """Settings of ``ob`` changed: its boards go, and a render still running for them is stopped (its folder too)."""
    _prewarps.pop(getattr(ob, "session_uid", None), None)
    live = MANAGER.boards.pop(getattr(ob, "session_uid", None), None)
    if live is not None and live.pending is not None:
        live.pending.cancel()


PREVIEW = Preview(_draw, topic=TOPIC, on_settings=_forget, replaces=previewing)
register = PREVIEW.register


def unregister():
    """Undo `register`; the boards' GPU data goes with it (its GPU context may not outlive the add-on)."""
    PREVIEW.unregister()
    if bpy.app.timers.is_registered(_redraw_now):
        bpy.app.timers.unregister(_redraw_now)
    _prewarps.clear()

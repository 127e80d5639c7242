"""Live nailboards ([Clua et al., §5]–B.6): which board an object is drawn from, and when a new one is asked for.

`NailboardManager.update(ob, eye, ...)` is called by the viewport every frame and never waits:
- a finished render is swapped in (double buffer: the old board is drawn until the new one is there); a job that
  offers a quick preview of its board (``job.preview()``, progressive delivery) has the preview swapped in first;
- a new board is asked for when there is none, at once when the object moved (its transform is part of the board),
  and otherwise only when the board fails the validity tests for this eye (`kernels.impostors.validity`: approach,
  parallax, resolution with tolerance K; a relief-mapped board's parallax counts at ``relief_factor``) and no render
  is already running;
- a request first looks in a cache of recent boards for one made near this viewpoint that is still valid there
  (returning to a viewpoint costs no render), and asks for the eye predicted ``lead`` frames ahead from the eye's
  velocity (the render is ready by the time the camera gets there).
- a board at least `RESAMPLE_AT` times finer than this view needs (eq. 8: zoomed out, a smaller viewport) is resampled
  down to `RESAMPLE_TO` times what it needs when a ``resample(images, resolution)`` is given (on a worker thread,
  swapped in when done): every frame pre-warps all the texels of the board drawn, so it then costs what a board made
  for this view would; the full board stays in the cache, and serves again if the view comes back.
- a render that fails is told once (``LiveBoard.failed``, shown by the panel) and asked for again only after a
  back-off that doubles with each failure (`RETRY_S` up to `RETRY_MAX_S`), never per frame.
The renderer is `addon.impostors.worker.request_board` (a separate process); the manager only needs its job's
``done()`` and ``result()``.
"""

import time
from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np

from ...kernels.common import workers
from ...kernels.common.errors import TesseraError
from ...kernels.impostors.validity import Board, check, sprite_resolution
from .worker import world_box


@dataclass
class LiveBoard:
    """One object's state: images and board (what it is drawn from, or None), the transform they were made with,
    the running job and the eyes of the last frames (for the velocity). The viewport keeps what it draws itself
    (`preview.Prewarp`)."""

    images: object = None
    board: Board = None
    matrix: bytes = b""
    pending: object = None
    pending_board: Board = None
    eyes: list = field(default_factory=list)
    previewing: bool = False  # drawn from the pending job's preview until its full render is there
    resampling: tuple = None  # (future of the resampled images, the images and Board it resamples, its resolution)
    keep: Board = None  # a board whose resampling failed: drawn as it is
    failed: str = ""  # why the last render failed ("" when it did not)
    failures: int = 0  # failures in a row
    retry_at: float = 0.0  # no new render is asked for before this time (time.monotonic)

    @property
    def state(self):
        """What the panel says: "Rendering", "Ready", "Waiting for the first render", or "Failed: ..."."""
        if self.pending is not None:
            return "Rendering (quick preview shown)" if self.previewing else "Rendering"
        if self.failed:
            return f"Failed, retrying in {max(0.0, self.retry_at - time.monotonic()):.0f} s: {self.failed}"
        return "Ready" if self.images is not None else "Waiting for the first render"


#: Seconds before a failed render is asked for again, doubled with each failure in a row, at most `RETRY_MAX_S`.
RETRY_S = 2.0
RETRY_MAX_S = 300.0
#: A board this many times finer than the eye needs is resampled ...
RESAMPLE_AT = 4
#: ... to this many times what it needs (the margin keeps it valid while the camera comes a little closer).
RESAMPLE_TO = 2


def _failed(live, ob, err):
    """Record that ``ob``'s board could not be made (`LiveBoard.failed`, shown in its panel), say so once, and wait
    longer before each new try."""
    live.failures += 1
    live.failed = str(err).strip().splitlines()[0][:300] if str(err).strip() else "the render failed"
    live.retry_at = time.monotonic() + min(RETRY_MAX_S, RETRY_S * 2 ** (live.failures - 1))
    print(f"Tessera: the nailboard of {ob.name!r} could not be rendered: {err}")


class NailboardManager:
    """Boards of every nailboard object, by ``session_uid``. request(ob, eye, res_screen, fov) -> a job;
    resample(images, resolution) -> the images at that resolution (`worker.resample_images`), or None: never."""

    def __init__(self, request, k=1.0, relief_factor=0.25, lead=0, cache_size=8, resample=None):
        self.request, self.k, self.relief_factor, self.lead = request, float(k), float(relief_factor), int(lead)
        self.resample = resample
        self.resamples = 0  # boards resampled down instead of drawn at a resolution the eye does not need
        self.boards, self.cache = {}, OrderedDict()
        self.cache_size = int(cache_size)
        self.regenerations = 0
        self.cache_hits = 0
        self.previews = 0  # previews swapped in before their full render
        self.reasons = []  # the `Verdict` of each regeneration a validity test asked for

    def update(self, ob, eye, res_screen, fov):
        """The `LiveBoard` to draw ``ob`` from at ``eye`` this frame (its ``images`` may still be None)."""
        eye = np.asarray(eye, np.float64)
        live = self.boards.setdefault(ob.session_uid, LiveBoard())
        live.eyes = (live.eyes + [eye])[-3:]
        matrix = np.array(ob.matrix_world).tobytes()
        if live.pending is not None and live.pending.done():
            job, live.pending, live.previewing = live.pending, None, False
            try:
                images = job.result()
            except TesseraError as err:  # told once; asked for again after the back-off
                _failed(live, ob, err)
            else:
                live.images, live.board = images, live.pending_board
                live.failed, live.failures = "", 0
                self.cache[(ob.session_uid, live.matrix, live.board.eye.tobytes())] = (live.images, live.board)
                while len(self.cache) > self.cache_size:
                    self.cache.popitem(last=False)
        elif live.pending is not None and not live.previewing:
            early = getattr(live.pending, "preview", lambda: None)()
            if early is not None:
                live.images, live.board, live.previewing = early, live.pending_board, True
                self.previews += 1
        moved = live.matrix != matrix
        if moved:
            if live.pending is not None:
                live.pending.cancel()
                live.pending, live.previewing = None, False
            live.images, live.board, live.matrix = None, None, matrix
        verdict = None if live.board is None else check(live.board, eye, fov, res_screen, self.k, self.relief_factor)
        stale = verdict is None or verdict.regenerate
        if stale and live.pending is None:
            if verdict is not None:
                self.reasons.append(verdict)
            hit = self._cached(ob, matrix, eye, res_screen, fov)
            if hit is not None:
                live.images, live.board = hit[0], hit[1]
                self.cache_hits += 1
            elif time.monotonic() >= live.retry_at:
                self._ask(ob, live, eye, res_screen, fov)
        elif self.resample is not None and not live.previewing:
            self._resample(live, eye, res_screen, fov)
        return live

    def _resample(self, live, eye, res_screen, fov):
        if live.resampling is not None:
            future, source, board, resolution = live.resampling
            if not future.done():
                return
            live.resampling = None
            if future.exception() is not None:
                print(f"Tessera: resampling a nailboard failed, it is drawn as rendered: {future.exception()}")
                live.keep = board
            elif live.images is source and live.board is board:  # nothing newer came in the meantime
                live.images = future.result()
                live.board = Board(board.eye, board.lo, board.hi, resolution)
                self.resamples += 1
            return
        board = live.board
        if board is live.keep:
            return
        distance = float(np.linalg.norm(eye - board.centre))
        size = float(np.linalg.norm(np.asarray(board.hi, np.float64) - np.asarray(board.lo, np.float64)))
        if distance <= size / 2:
            return
        needed = sprite_resolution(res_screen, size, distance, fov)
        if board.resolution >= RESAMPLE_AT * needed:
            resolution = RESAMPLE_TO * needed
            live.resampling = (workers.submit(self.resample, live.images, resolution), live.images, board, resolution)

    def _cached(self, ob, matrix, eye, res_screen, fov):
        for key in reversed(self.cache):
            if key[:2] != (ob.session_uid, matrix):
                continue
            images, board = self.cache[key]
            if not check(board, eye, fov, res_screen, self.k, self.relief_factor).regenerate:
                return images, board
        return None

    def _ask(self, ob, live, eye, res_screen, fov):
        target = eye
        if self.lead and len(live.eyes) >= 2:  # velocity prediction, `lead` frames ahead
            target = eye + self.lead * (live.eyes[-1] - live.eyes[-2])
        try:
            job = self.request(ob, target, res_screen, fov)
        except TesseraError as err:  # refused before it started (nothing to render): told once, asked again later
            _failed(live, ob, err)
            return
        lo, hi = world_box(ob)
        live.pending = job
        live.pending_board = Board(np.asarray(target, np.float64), lo, hi, job.setup.resolution)
        self.regenerations += 1

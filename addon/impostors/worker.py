"""The renderer side of nailboards ([Clua et al., §5]): a board is rendered by a separate Blender process (niced where
the OS allows), so the viewport never waits for it. `request_board` writes what the render needs (`write_job`: the
object and what it depends on, the scene's lights and world, nothing else), starts the process on
`worker_script.py` and returns at once a `BoardJob`; `BoardJob.done()` polls without blocking and, once the process
has finished, reads its images on a worker thread (colour, displacement from the depth pass, normals, where the
object is), so the main thread never reads a file either; `BoardJob.result()` hands them over.
"""

import json
import os
import subprocess
from concurrent import futures
from dataclasses import dataclass
from pathlib import Path

import bpy
import numpy as np

from ...kernels.common import workers
from ...kernels.common.errors import TesseraError
from ...kernels.common.image_io import read_channels
from ...kernels.common.tolerances import ALPHA_FLOOR
from ...kernels.impostors.board import board_setup
from ...kernels.impostors.resample import resample_board
from .. import render_jobs
from ..compat import RENDER_STATS_IN_WORKERS
from ..render_jobs import job_folder, remove_folder, render_device, stop_process, track
from ..viewport import source_mesh

SCRIPT = Path(__file__).with_name("worker_script.py")


@dataclass
class BoardImages:
    """A rendered board: setup (`kernels.impostors.board.BoardSetup`); colours (H, W, 4) float32 (straight
    alpha), displacement (H, W) float64, normals (H, W, 3) float32, present (H, W) bool; row 0 at v = 0."""

    setup: object
    colours: np.ndarray
    displacement: np.ndarray
    normals: np.ndarray
    present: np.ndarray


def write_job(ob, folder, resolution, samples, scale, clip, views, device=None):
    """Write a render job for the worker into ``folder`` and return the job file's path.

    ``scene.blend`` holds ``ob`` with what it depends on (mesh, materials, images, the objects its modifiers use),
    the lights of the view layer that render and the scene's world: only these (``bpy.data.libraries.write``, with
    absolute paths), so the main thread's pause does not grow with the scene the way saving a copy of the file does.
    ``job.json`` names them, with the world matrix of every object (the worker places them in a scene of their own,
    unparented) and the views: dicts of ``location``, ``forward``, ``up`` (3 floats each) and ``out`` (an EXR path),
    and optionally ``preview``: ``{"samples", "out"}``, a quicker render of the view written first; ``device``: the
    Cycles device to render on (`render_jobs.render_device`; default: the user's).
    """
    if ob.mode == "EDIT":  # what is being edited is not in the mesh until flushed (saving a file would flush it)
        ob.update_from_editmode()
    scene = bpy.context.scene
    # the lights that render in this view layer (not those of excluded collections or hidden from renders)
    lights = [o for o in bpy.context.view_layer.objects if o.type == "LIGHT" and not o.hide_render and o is not ob]
    blocks = {ob, *lights}
    if scene.world is not None:
        blocks.add(scene.world)
    blend = os.path.join(folder, "scene.blend")
    bpy.data.libraries.write(blend, blocks, path_remap="ABSOLUTE", fake_user=True)
    job = {"blend": blend, "object": ob.name, "lights": [o.name for o in lights],
           "world": None if scene.world is None else scene.world.name,
           "matrices": {o.name: [list(row) for row in o.matrix_world] for o in (ob, *lights)},
           "resolution": int(resolution), "samples": int(samples), "scale": float(scale), "clip": float(clip),
           "views": views, "device": device if device is not None else render_device(),
           "report_samples": RENDER_STATS_IN_WORKERS}
    path = os.path.join(folder, "job.json")
    with open(path, "w", encoding="utf-8") as f:
        json.dump(job, f)
    return path


def start_worker(job_file, log_path):
    """Start the board and atlas worker (`worker_script.py`) on a job file (`write_job`): `render_jobs.start_worker`."""
    return render_jobs.start_worker(SCRIPT, job_file, log_path)


class BoardJob:
    """One board being rendered: ``done()`` never blocks; ``result()`` waits for it (or use it once done);
    ``poll()`` (a timer's job, never the draw callback's: it looks for files) starts reading what the worker has
    written; ``preview()`` then gives the quick first render of a progressive job, without waiting."""

    def __init__(self, setup, process, folder, out, preview_out=None):
        self.setup, self.process, self.folder, self.out = setup, process, folder, out
        self.preview_out = preview_out
        track(folder, self)  # stopped with the add-on or Blender if still running
        self._images = None  # the reading of the images (a future), started once the process has finished
        self._preview = None  # the reading of the preview's images, started once its file is there

    def poll(self):
        """Start reading, on a worker thread, the preview once the worker has moved it into place and the final images
        once the process has finished; never blocks."""
        if self.preview_out is not None and self._preview is None and os.path.isfile(self.preview_out):
            self._preview = workers.submit(self._read_images, self.preview_out)
        self.done()

    def preview(self):
        """The `BoardImages` of the preview render (few samples: the same board, noisier colours) once `poll` has had
        it read, else None; never blocks and touches no file."""
        if self._preview is None or not self._preview.done() or self._preview.exception() is not None:
            return None
        return self._preview.result()

    def done(self):
        """Whether the board is rendered and its images read (their reading starts, on a worker thread, at the first
        call that finds the process finished)."""
        if self._images is None and self.process.poll() is not None:
            self._images = workers.submit(self._read)
        return self._images is not None and self._images.done()

    def result(self, timeout=None):
        """The `BoardImages`, waiting up to ``timeout`` seconds for the render (None: as long as it takes)."""
        try:
            self.process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            raise TesseraError("The board is still being rendered") from None
        if self._images is None:
            self._images = workers.submit(self._read)
        return self._images.result()

    def _read(self):
        try:
            if self.process.returncode != 0 or not os.path.isfile(self.out):
                log = Path(self.folder, "worker.log").read_bytes()
                if self.process.returncode == 0:  # it ended as if done, without the board
                    raise TesseraError(f"Rendering the board failed: the render process wrote no board: "
                                       f"{log[-300:].decode('utf-8', 'replace').strip()}")
                raise TesseraError(render_jobs.failure("Rendering the board", self.process.returncode, log))
            if self._preview is not None:
                futures.wait([self._preview])  # the preview's reading is done with the folder too
            return self._read_images(self.out)
        finally:
            remove_folder(self.folder)  # read or failed: nothing of the job stays on disk

    def _read_images(self, path):
        r, g, b, a, z, nx, ny, nz = read_channels(path, "board render", (
            "Combined.R", "Combined.G", "Combined.B", "Combined.A", "Depth.Z", "Normal.X", "Normal.Y", "Normal.Z"))
        present = a > 0.5
        alpha = np.maximum(a, ALPHA_FLOOR)[..., None]
        colours = np.concatenate([np.stack([r, g, b], -1) / alpha, a[..., None]], -1).astype(np.float32)
        d = np.where(present, self.setup.displacement(z), 0.0)
        return BoardImages(self.setup, colours, d, np.stack([nx, ny, nz], -1), present)

    def cancel(self):
        """Stop the worker and remove the folder once the process is gone (a process that does not end in time leaves
        it to the sweep at the next start)."""
        if stop_process(self.process):
            remove_folder(self.folder)


def resample_images(images, resolution):
    """`BoardImages` resampled to ``resolution`` texels a side (`kernels.impostors.resample.resample_board`)."""
    setup, colours, displacement, normals, present = resample_board(
        images.setup, images.colours, images.displacement, images.normals, images.present, resolution)
    return BoardImages(setup, colours, displacement, normals, present)


def check_renderable(ob, depsgraph=None):
    """Raise `TesseraError` when ``ob`` would render nothing or garbage: no faces once evaluated (an empty curve, a
    mesh of loose points), or vertices that are not numbers (NaN or infinite), which would fill the images with
    non-finite pixels."""
    mesh, release = source_mesh(ob, depsgraph or bpy.context.evaluated_depsgraph_get())  # under a preview too
    try:
        faces = 0 if mesh is None else len(mesh.polygons)
        bad = 0
        if faces:
            pos = np.empty(len(mesh.vertices) * 3, np.float32)
            mesh.vertices.foreach_get("co", pos)
            bad = int((~np.isfinite(pos.reshape(-1, 3))).any(axis=1).sum())
    finally:
        release()
    if not faces:
        raise TesseraError(f"{ob.name!r} has no faces to render (an empty curve or loose points render nothing): "
                           "give it geometry, or pick another object")
    if bad:
        raise TesseraError(f"{ob.name!r} has {bad:,} vertices that are not numbers (NaN or infinite): fix or delete "
                           "them, then try again")
    if not np.isfinite(np.array(ob.matrix_world)).all():
        raise TesseraError(f"{ob.name!r} has a transform that is not made of numbers: reset it (Alt+G, Alt+R, Alt+S)")


def world_box(ob):
    """The world-space axis-aligned box around ``ob``'s bounding box: ``(lo, hi)``, each (3,) float64."""
    from mathutils import Vector

    corners = np.array([ob.matrix_world @ Vector(c) for c in ob.bound_box], np.float64)
    return corners.min(axis=0), corners.max(axis=0)


#: A board rendered with at least this many samples is rendered first with `preview_samples` (progressive delivery).
PROGRESSIVE_MIN_SAMPLES = 8


def preview_samples(samples):
    """Samples of the quick first render of a board of ``samples`` samples (a sixteenth, at least 1)."""
    return max(1, int(samples) // 16)


def request_board(ob, eye, res_screen, fov, samples=8, rounding="CEIL", setup=None, progressive=True):
    """Start rendering ``ob``'s board for ``eye`` (world space; a camera of ``res_screen`` pixels and ``fov``
    radians): a `BoardJob`, at once. The board is in world space (the object's bounding box in world space), or
    ``setup`` (a `BoardSetup` already made for this object and eye) when given. progressive: from
    `PROGRESSIVE_MIN_SAMPLES` samples, the worker first renders the board with `preview_samples` and writes it
    (`BoardJob.preview`), then renders it in full."""
    if setup is None:
        check_renderable(ob)
        setup = board_setup(*world_box(ob), eye, res_screen, fov, rounding)
    folder = job_folder("board")
    out = os.path.join(folder, "board.exr")
    view = {"location": [float(x) for x in setup.camera_location], "forward": [float(x) for x in setup.camera_forward],
            "up": [float(x) for x in setup.camera_up], "out": out}
    preview_out = None
    if progressive and samples >= PROGRESSIVE_MIN_SAMPLES:
        preview_out = os.path.join(folder, "preview.exr")
        view["preview"] = {"samples": preview_samples(samples), "out": preview_out}
    try:
        job = write_job(ob, folder, setup.resolution, samples, setup.size, 2 * setup.size, [view])
        return BoardJob(setup, start_worker(job, os.path.join(folder, "worker.log")), folder, out, preview_out)
    except BaseException:
        remove_folder(folder)
        raise


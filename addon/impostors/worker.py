"""The renderer side of nailboards (seed 003 §B.5): a board is rendered by a separate Blender process (niced where
the OS allows), so the viewport never waits for it. `request_board` saves a copy of the file, starts the process on
`worker_script.py` and returns at once a `BoardJob`; `BoardJob.done()` polls without blocking, `BoardJob.result()`
reads the images (colour, displacement from the depth pass, normals, where the object is) once it is done.
"""

import os
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import bpy
import numpy as np

from ...kernels.common.errors import TesseraError
from ...kernels.common.image_io import read_channels
from ...kernels.impostors.board import board_setup

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


def worker_command(blend, args):
    """The worker's command line: the blender binary where there is one, else this Python with the bpy module."""
    binary = getattr(bpy.app, "binary_path", "")
    if binary and os.path.basename(binary).lower().startswith("blender") and os.path.isfile(binary):
        return [binary, "--background", "--factory-startup", blend, "--python", str(SCRIPT), "--", blend, *args]
    return [sys.executable, str(SCRIPT), "--", blend, *args]


def lower_priority():
    if hasattr(os, "nice"):
        os.nice(10)  # below the viewport's priority (seed: the CPU cluster's "low-priority thread")


class BoardJob:
    """One board being rendered: ``done()`` never blocks; ``result()`` waits for it (or use it once done)."""

    def __init__(self, setup, process, folder, out):
        self.setup, self.process, self.folder, self.out = setup, process, folder, out

    def done(self):
        return self.process.poll() is not None

    def result(self, timeout=None):
        try:
            self.process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            raise TesseraError("The board is still being rendered") from None
        if self.process.returncode != 0 or not os.path.isfile(self.out):
            tail = Path(self.folder, "worker.log").read_text(errors="replace")[-600:]
            raise TesseraError(f"Rendering the board failed (exit {self.process.returncode}): {tail}")
        r, g, b, a, z, nx, ny, nz = read_channels(self.out, "board render", (
            "Combined.R", "Combined.G", "Combined.B", "Combined.A", "Depth.Z", "Normal.X", "Normal.Y", "Normal.Z"))
        present = a > 0.5
        alpha = np.maximum(a, 1e-6)[..., None]
        colours = np.concatenate([np.stack([r, g, b], -1) / alpha, a[..., None]], -1).astype(np.float32)
        d = np.where(present, self.setup.displacement(z), 0.0)
        return BoardImages(self.setup, colours, d, np.stack([nx, ny, nz], -1), present)

    def cancel(self):
        if self.process.poll() is None:
            self.process.kill()


def world_box(ob):
    """The world-space axis-aligned box around ``ob``'s bounding box: ``(lo, hi)``, each (3,) float64."""
    from mathutils import Vector

    corners = np.array([ob.matrix_world @ Vector(c) for c in ob.bound_box], np.float64)
    return corners.min(axis=0), corners.max(axis=0)


def request_board(ob, eye, res_screen, fov, samples=8, rounding="CEIL", setup=None):
    """Start rendering ``ob``'s board for ``eye`` (world space; a camera of ``res_screen`` pixels and ``fov``
    radians): a `BoardJob`, at once. The board is in world space (the object's bounding box in world space), or
    ``setup`` (a `BoardSetup` already made for this object and eye) when given."""
    if setup is None:
        setup = board_setup(*world_box(ob), eye, res_screen, fov, rounding)
    folder = tempfile.mkdtemp(prefix="tessera-board-")
    blend = os.path.join(folder, "scene.blend")
    bpy.ops.wm.save_as_mainfile(filepath=blend, copy=True)
    out = os.path.join(folder, "board.exr")
    args = [ob.name, out, str(setup.resolution), str(int(samples)),
            *(repr(float(x)) for v in (setup.camera_location, setup.camera_forward, setup.camera_up) for x in v),
            repr(float(setup.size)), repr(float(2 * setup.size))]
    log = open(os.path.join(folder, "worker.log"), "wb")  # a file, not a pipe: a chatty worker never stalls
    kwargs = {"stdout": log, "stderr": subprocess.STDOUT}
    if os.name == "posix":
        kwargs["preexec_fn"] = lower_priority
    try:
        process = subprocess.Popen(worker_command(blend, args), **kwargs)
    finally:
        log.close()
    return BoardJob(setup, process, folder, out)


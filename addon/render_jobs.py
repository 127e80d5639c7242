"""Background renders: the one mechanism every render Tessera runs in a worker process goes through (impostor atlases,
nailboards, the lighting bake for Loop subdivision, and any later one). `start_worker` starts a worker script; the
scripts share `worker_device.py` (the user's Cycles device on the worker's side).

- **Folders**: each job works in a folder of its own, ``tessera-<kind>-*`` in the system's temporary directory, with
  the id of the process that made it (`job_folder`). The folder is removed as soon as the job's result is read, on
  failure and on cancel (`RenderJob.close`), for every job still open when the add-on is disabled or Blender exits
  (`close_all`), and folders that a Blender which crashed left behind are removed at the next enable
  (`remove_stale_folders`: only Tessera's kinds, only when their process is gone or they are old).
- **Progress**: the worker prints ``TESSERA_PROGRESS k/n`` after each view and ``TESSERA_DEVICE ...`` once it knows
  what it renders on; `RenderJob.progress` reads them from the log without blocking (the UI polls from a timer;
  `RenderJob.fraction` adds the share of the current view from its ``TESSERA_SAMPLES k/n`` lines), and
  `RenderJob.wait` follows them to the end where nothing can poll (``blender -b``, the ``bpy`` module), printing a
  line per step so scripts show progress.
- **Device**: `render_device` gives the worker the Cycles device the user chose in the preferences (GPU where one is
  configured and the scene renders on it), the CPU when nothing else is set.
"""

import atexit
import hashlib
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

import bpy
import numpy as np

from ..kernels.common.errors import TesseraError

#: The kinds of job folders; only these are ever removed as stale.
KINDS = ("impostor", "board", "bake", "library")
#: A folder of a process that is gone is stale after this many seconds; any folder of ours after `STALE_AGE_S`.
ORPHAN_AGE_S = 60.0
STALE_AGE_S = 24 * 3600.0
_OWNER = "owner.pid"
_DEVICE = re.compile(rb"TESSERA_DEVICE ([^\r\n]+)")
#: A worker's progress lines: its step lines, and the samples of the render under way (`worker_device.report_samples`),
#: so progress moves within a step.
_STEPS = re.compile(rb"TESSERA_PROGRESS (\d+)/\d+|TESSERA_SAMPLES (\d+)/(\d+)")

_open_jobs = {}  # folder -> RenderJob (or None while the job is being set up)


def job_folder(kind):
    """A new folder for a job of ``kind`` (one of `KINDS`), owned by this process until `remove_folder`."""
    if kind not in KINDS:
        raise ValueError(f"unknown job kind {kind!r}")
    folder = tempfile.mkdtemp(prefix=f"tessera-{kind}-")
    with open(os.path.join(folder, _OWNER), "w", encoding="ascii") as f:
        f.write(str(os.getpid()))
    _open_jobs[folder] = None
    return folder


def stop_process(process, timeout=10.0):
    """Stop a worker process still running and wait for it: whether it has ended. A leashed worker (`start_worker`)
    is let go by closing its leash's pipe (the leash kills it and removes its folder), then killed if it lingers."""
    leash = getattr(process, "stdin", None)
    if leash is not None and not leash.closed:
        try:
            leash.close()
        except OSError:
            pass
        try:
            process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            pass
    if process.poll() is None:
        process.kill()
        try:
            process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            return False
    return True


def track(folder, job):
    """Count ``job`` (anything with ``cancel()``: a nailboard's job) as the job of ``folder``, so that `close_all`
    stops it with the add-on or Blender."""
    _open_jobs[folder] = job


def remove_folder(folder):
    """Remove a job folder and forget it (nothing happens when it is gone already)."""
    _open_jobs.pop(folder, None)
    shutil.rmtree(folder, ignore_errors=True)


def open_folders():
    """The job folders this process has not removed yet."""
    return list(_open_jobs)


def is_alive(pid):
    if os.name != "posix":
        return True  # no cheap check: only age decides
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # it exists, owned by someone else
        return True
    return True


def remove_stale_folders(root=None, now=None):
    """Remove the job folders (of `KINDS`) that no running process owns: their process is gone and they are older than
    `ORPHAN_AGE_S`, or they are older than `STALE_AGE_S`. Returns the folders removed."""
    root = root or tempfile.gettempdir()
    now = time.time() if now is None else now
    removed = []
    try:
        names = os.listdir(root)
    except OSError:
        return removed
    for name in names:
        if not any(name.startswith(f"tessera-{kind}-") for kind in KINDS):
            continue
        folder = os.path.join(root, name)
        if folder in _open_jobs or not os.path.isdir(folder):
            continue
        try:
            age = now - os.path.getmtime(folder)
            with open(os.path.join(folder, _OWNER), encoding="ascii") as f:
                owner = int(f.read().strip() or 0)
        except (OSError, ValueError):
            owner = 0
            try:
                age = now - os.path.getmtime(folder)
            except OSError:
                continue
        if age > STALE_AGE_S or (age > ORPHAN_AGE_S and not (owner and is_alive(owner))):
            shutil.rmtree(folder, ignore_errors=True)
            removed.append(folder)
    return removed


def worker_command(script, job_file):
    """The command line of worker ``script`` (a path) on ``job_file``: the blender binary where there is one, else this
    Python with the bpy module."""
    binary = getattr(bpy.app, "binary_path", "")
    if binary and os.path.basename(binary).lower().startswith("blender") and os.path.isfile(binary):
        return [binary, "--background", "--factory-startup", "--python", str(script), "--", str(job_file)]
    return [sys.executable, str(script), "--", str(job_file)]


#: The leash every worker runs on (`worker_leash.py`): it never outlives the Blender that started it.
LEASH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "worker_leash.py")


def _python():
    """The Python this Blender runs (its own, or the system's in a distribution's build), when it is a Python
    program; else None."""
    exe = sys.executable or ""
    return exe if os.path.basename(exe).lower().startswith("python") and os.path.isfile(exe) else None


def start_worker(script, job_file, log_path):
    """Start worker ``script`` on ``job_file``, its output going to ``log_path`` (a file, not a pipe: a chatty
    worker never stalls), below the viewport's priority ([Clua et al.]'s "low-priority thread": nice 10 on POSIX, below
    normal on Windows), on a leash (`worker_leash.py`): when this process ends, however it ends, the worker is killed
    and its job folder (the job file's) removed. Returns the `subprocess.Popen` (of the leash; its ``stdin`` is the
    leash's pipe, which `stop_process` closes)."""
    command = worker_command(script, job_file)
    python = _python()
    kwargs = {}
    if os.name == "nt":
        kwargs["creationflags"] = subprocess.BELOW_NORMAL_PRIORITY_CLASS
    with open(log_path, "wb") as log:
        if python is not None:
            folder = os.path.dirname(os.path.abspath(job_file))
            folder = folder if folder in _open_jobs else ""  # only a job's own folder is ever removed by the leash
            process = subprocess.Popen([python, "-I", LEASH, folder, "--", *command], stdin=subprocess.PIPE,
                                       stdout=log, stderr=subprocess.STDOUT, **kwargs)
        else:
            process = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT, **kwargs)
    if hasattr(os, "setpriority"):
        try:
            os.setpriority(os.PRIO_PROCESS, process.pid, 10)
        except OSError:  # it has finished already, or the system does not let us: it runs at normal priority
            pass
    return process


#: What a signal that ended a worker means, in the user's words.
_SIGNALS = {"SIGKILL": "it was killed (SIGKILL; most often the system ran out of memory)",
            "SIGSEGV": "it crashed (SIGSEGV)", "SIGABRT": "it aborted (SIGABRT)", "SIGBUS": "it crashed (SIGBUS)",
            "SIGTERM": "it was stopped (SIGTERM)", "SIGINT": "it was interrupted (SIGINT)"}
_ERROR_LINE = re.compile(r"error|exception|failed|out of memory|cannot|could not", re.IGNORECASE)


def failure(what, code, log):
    """One sentence for a worker that ended with exit ``code`` (negative: the signal) and ``log`` (bytes): why it
    ended, and the last line of its log that says what went wrong (not Blender's start-up lines)."""
    import signal

    if code < 0:
        try:
            name = signal.Signals(-code).name
        except ValueError:
            name = f"signal {-code}"
        reason = _SIGNALS.get(name, f"it was ended by {name}")
    else:
        reason = f"it exited with code {code}"
    lines = [ln.strip() for ln in log.decode("utf-8", "replace").splitlines() if ln.strip()]
    said = [ln for ln in lines if _ERROR_LINE.search(ln) and not ln.startswith("Traceback")]
    detail = said[-1] if said else ""
    return f"{what} failed: the render process ended early ({reason})" + (f": {detail[:300]}" if detail else "")


def render_device(context=None):
    """The Cycles device the user chose, for a worker: ``{"type": "NONE" | "CUDA" | "OPTIX" | "HIP" | "METAL" |
    "ONEAPI", "devices": [ids of the devices in use], "gpu": whether the scene renders on the GPU}``. A worker given
    ``gpu`` False, or type NONE, renders on the CPU."""
    context = context or bpy.context
    scene_gpu = getattr(getattr(context.scene, "cycles", None), "device", "CPU") == "GPU"
    addon = context.preferences.addons.get("cycles")
    prefs = getattr(addon, "preferences", None)
    kind = getattr(prefs, "compute_device_type", "NONE") if prefs is not None else "NONE"
    devices = [d.id for d in getattr(prefs, "devices", ()) if getattr(d, "use", False) and d.type != "CPU"] \
        if prefs is not None else []
    return {"type": kind or "NONE", "devices": devices, "gpu": bool(scene_gpu and kind not in ("", "NONE"))}


def _mesh_digest(digest, ob, depsgraph=None):
    """Add ``ob``'s vertex positions (evaluated with ``depsgraph``, else its own mesh) to ``digest``."""
    source = ob.evaluated_get(depsgraph) if depsgraph is not None else ob
    try:
        mesh = source.to_mesh() if depsgraph is not None else ob.data
        if mesh is None:  # nothing to render (an empty curve)
            return
        pos = np.empty(len(mesh.vertices) * 3, np.float32)
        mesh.vertices.foreach_get("co", pos)
        digest.update(pos.tobytes())
    finally:
        if depsgraph is not None:
            source.to_mesh_clear()


def render_key(context, ob, surroundings=False):
    """What a render of ``ob`` depends on, to tell whether a redo must render again: its evaluated geometry,
    transform and materials, the lights that render (and, with ``surroundings``, every other object that renders: its
    transform and mesh, for a bake of the light bounced off them), the world and the user's render device. A tuple."""
    digest = hashlib.sha256()
    _mesh_digest(digest, ob, context.evaluated_depsgraph_get())
    digest.update(np.array(ob.matrix_world, np.float64).tobytes())
    for o in context.view_layer.objects:
        if o is ob or o.hide_render or not (o.type == "LIGHT" or surroundings):
            continue
        digest.update(o.name.encode() + np.array(o.matrix_world, np.float64).tobytes())
        if surroundings and o.type == "MESH":
            _mesh_digest(digest, o)
    names = [m.name for m in getattr(ob.data, "materials", ()) if m is not None]
    world = context.scene.world.name if context.scene.world else ""
    return ob.session_uid, digest.hexdigest(), tuple(names), world, str(render_device(context))


class RenderJob:
    """A worker process rendering into ``folder``: ``total`` steps (views); ``log`` the file its output goes to."""

    def __init__(self, process, folder, total, log):
        self.process, self.folder, self.total, self.log = process, folder, int(total), log
        self._read, self._partial, self._done, self._device = 0, b"", 0, ""
        self._within = 0.0  # the share of the current step done (its render's samples)
        _open_jobs[folder] = self

    def _log_bytes(self):
        try:
            with open(self.log, "rb") as f:
                return f.read()
        except OSError:
            return b""

    def _scan(self):
        """Read what the worker wrote since the last call (whole lines) for its progress and device lines: a poll
        costs what is new, not the whole log."""
        try:
            with open(self.log, "rb") as f:
                f.seek(self._read)
                new = f.read()
        except OSError:
            return
        self._read += len(new)
        text = self._partial + new
        cut = text.rfind(b"\n") + 1
        lines, self._partial = text[:cut], text[cut:]
        for step, sample, samples in _STEPS.findall(lines):
            if step:
                self._done, self._within = int(step), 0.0
            elif int(samples) > 0:
                self._within = min(int(sample) / int(samples), 1.0)
        found = _DEVICE.search(lines)
        if found and not self._device:
            self._device = found.group(1).decode("utf-8", "replace").strip()

    def progress(self):
        """Steps done so far (from the worker's log; never blocks): int."""
        self._scan()
        return self._done

    def fraction(self):
        """Steps done so far and the share of the current one its render has sampled (never blocks): float."""
        self._scan()
        return self._done + (self._within if self._done < self.total else 0.0)

    def device(self):
        """What the worker said it renders on, or "" before it says."""
        self._scan()
        return self._device

    def running(self):
        return self.process.poll() is None

    def tail(self):
        """The end of the worker's log (what it said last): str."""
        return self._log_bytes()[-600:].decode("utf-8", "replace")

    def check(self, what):
        """Raise `TesseraError` with the end of the worker's log when it failed (``what``: "Baking the impostor")."""
        code = self.process.poll()
        if code is not None and code != 0:
            raise TesseraError(failure(what, code, self._log_bytes()))

    def wait(self, report=None, what="Rendering", timeout=None):
        """Follow the job to its end where nothing polls it (background mode, the ``bpy`` module): ``report(line)``
        gets a line per step done (default: print). Raises `TesseraError` on failure or after ``timeout`` seconds."""
        report = report or (lambda line: print(line, flush=True))
        start, shown = time.monotonic(), 0
        while self.running():
            done = self.progress()
            if done != shown:
                shown = done
                report(f"Tessera: {what} {done}/{self.total}")
            if timeout is not None and time.monotonic() - start > timeout:
                self.cancel()
                raise TesseraError(f"{what} took longer than {timeout:g} s and was stopped")
            time.sleep(0.1)
        if self.progress() != shown:
            report(f"Tessera: {what} {self.progress()}/{self.total}")
        self.check(what)

    def cancel(self):
        """Stop the worker and remove the folder: nothing of the job is left."""
        stop_process(self.process)
        remove_folder(self.folder)

    def close(self):
        """The result is read (or the job failed): remove the folder."""
        remove_folder(self.folder)


def close_all():
    """Stop every open job and remove every job folder of this process (the add-on is disabled, Blender exits)."""
    for folder, job in list(_open_jobs.items()):
        if job is not None:
            job.cancel()
        else:
            remove_folder(folder)


atexit.register(close_all)


def register():
    remove_stale_folders()


def unregister():
    close_all()

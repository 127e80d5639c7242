"""Files in and out of the command line: scenes and meshes read through Blender's importers, results written through
Blender's exporters under a temporary name, checked whole (`written`) and renamed when every output of the run is,
so a task that fails, is stopped or is killed never leaves a half file under the name asked for.

Output names may hold ``{object}`` (one file per source object) and ``{frame}`` or ``#``s (one per frame, the ``#``s
giving the zero-padded width, as Blender's render output does).
"""

import errno
import glob
import os
import re
import shutil
import socket
import sys
from contextlib import contextmanager
from dataclasses import dataclass

import bpy

from ...kernels.common import written
from .. import render_jobs
from . import stopping

#: Importers by file extension: (operator path, keyword arguments).
IMPORTERS = {
    ".obj": ("wm.obj_import", {}),
    ".ply": ("wm.ply_import", {}),
    ".stl": ("wm.stl_import", {}),
    ".glb": ("import_scene.gltf", {}),
    ".gltf": ("import_scene.gltf", {}),
    ".usd": ("wm.usd_import", {}),
    ".usda": ("wm.usd_import", {}),
    ".usdc": ("wm.usd_import", {}),
    ".usdz": ("wm.usd_import", {}),
    ".abc": ("wm.alembic_import", {}),
    ".fbx": ("import_scene.fbx", {}),
}
#: Exporters by extension: (operator path, keyword arguments; the selection is what is written).
EXPORTERS = {
    ".obj": ("wm.obj_export", {"export_selected_objects": True}),
    ".ply": ("wm.ply_export", {"export_selected_objects": True}),
    ".stl": ("wm.stl_export", {"export_selected_objects": True}),
    ".glb": ("export_scene.gltf", {"export_format": "GLB", "use_selection": True}),
    ".gltf": ("export_scene.gltf", {"export_format": "GLTF_SEPARATE", "use_selection": True}),
    ".usd": ("wm.usd_export", {"selected_objects_only": True}),
    ".usda": ("wm.usd_export", {"selected_objects_only": True}),
    ".usdc": ("wm.usd_export", {"selected_objects_only": True}),
    ".usdz": ("wm.usd_export", {"selected_objects_only": True}),
    ".abc": ("wm.alembic_export", {"selected": True}),
    ".fbx": ("export_scene.fbx", {"use_selection": True}),
}
#: Core add-ons that carry some of the importers and exporters.
_IO_ADDONS = {"import_scene.gltf": "io_scene_gltf2", "export_scene.gltf": "io_scene_gltf2",
              "import_scene.fbx": "io_scene_fbx", "export_scene.fbx": "io_scene_fbx"}
#: Formats whose file names others beside it (.gltf: its .bin and textures; .obj: its .mtl): written under their final
#: names in a folder of their own, then moved.
_SIDECARS = (".gltf", ".obj")
_PARTIAL = re.compile(r"^\..*\.tessera-partial-(?P<host>[^-]+)-(?P<pid>\d+)(\.[^.]*)?$")
_HASHES = re.compile(r"#+")


class FileProblem(Exception):
    """A file argument that cannot be used (exit code 2): the message says why."""


class WriteFailed(Exception):
    """An output that could not be written whole (exit code 1): one sentence naming the path and the cause."""


def extension(path):
    return os.path.splitext(path)[1].lower()


def check_output(path, allowed=None):
    """Refuse an output whose format Blender cannot write here (or, with ``allowed``, this verb cannot)."""
    ext = extension(path)
    known = set(EXPORTERS) | {".blend"} if allowed is None else set(allowed)
    if ext not in known:
        raise FileProblem(f"{path}: cannot write {ext or 'a file without an extension'}; use one of "
                          f"{', '.join(sorted(known))}")
    if ext in EXPORTERS and not available(EXPORTERS[ext][0]):
        raise FileProblem(f"{path}: this Blender was built without the {ext} exporter (distributions' builds may "
                          f"leave out USD or Alembic); use one of {', '.join(sorted(writable(known)))}")


def available(op_path):
    """Whether this Blender has the importer or exporter ``op_path`` ("wm.usd_export"; its core add-on enabled)."""
    try:
        _operator(op_path).get_rna_type()
    except (AttributeError, KeyError, RuntimeError, ModuleNotFoundError):
        return False
    return True


def writable(formats):
    """The extensions of ``formats`` this Blender can write."""
    return [ext for ext in formats if ext not in EXPORTERS or available(EXPORTERS[ext][0])]


def _operator(path):
    module, name = path.split(".")
    addon = _IO_ADDONS.get(path)
    if addon is not None:
        import addon_utils

        if not addon_utils.check(addon)[1]:
            addon_utils.enable(addon, default_set=False)
    return getattr(getattr(bpy.ops, module), name)


#: How the files Blender saves begin: uncompressed, zstd (Blender 3.0+), gzip (before).
_BLEND_MAGIC = (b"BLENDER", b"\x28\xb5\x2f\xfd", b"\x1f\x8b")


def check_input(path, readable):
    """Raise `FileProblem` unless ``path`` is a file this process can read, of an extension in ``readable``; a .blend
    must begin as Blender's files do."""
    path = os.path.abspath(path)
    if os.path.isdir(path):
        raise FileProblem(f"{path}: is a folder; give a file")
    if not os.path.exists(path):
        raise FileProblem(f"{path}: no such file")
    ext = extension(path)
    if ext not in readable:
        raise FileProblem(f"{path}: cannot read {ext or 'a file without an extension'}; give "
                          f"{', '.join(sorted(readable))}")
    try:
        with open(path, "rb") as f:
            head = f.read(7)
    except OSError as err:
        raise FileProblem(f"{path}: cannot be read: {written.os_cause(err)}") from None
    if ext == ".blend" and not head.startswith(_BLEND_MAGIC):
        raise FileProblem(f"{path}: is not a Blender file (it does not begin as a .blend does)")
    if ext in IMPORTERS and not available(IMPORTERS[ext][0]):
        raise FileProblem(f"{path}: this Blender was built without the {ext} importer (distributions' builds may "
                          "leave out USD or Alembic); export it as .glb, .obj or .ply and give that")


def read_inputs(paths):
    """Open the scene and import the meshes named by ``paths``: a .blend is opened (at most one, first); other files
    are imported into it, or into an empty scene when no .blend is given. Returns the objects the imports added."""
    paths = [os.path.abspath(p) for p in paths]
    for p in paths:
        check_input(p, {".blend", *IMPORTERS})
    blends = [p for p in paths if extension(p) == ".blend"]
    if len(blends) > 1:
        raise FileProblem(f"Give one .blend at most (the scene); got {len(blends)}")
    if blends:
        bpy.ops.wm.open_mainfile(filepath=blends[0], load_ui=False)
    elif paths:
        bpy.ops.wm.read_homefile(use_empty=True)
    return read_inputs_into_scene([p for p in paths if extension(p) != ".blend"])


def read_inputs_into_scene(paths):
    """Import the mesh files ``paths`` into the current scene: the objects they added."""
    imported = []
    for p in paths:
        before = set(bpy.data.objects)
        op, kw = IMPORTERS[extension(p)]
        _operator(op)(filepath=p, **kw)
        imported += [ob for ob in bpy.data.objects if ob not in before]
    return imported


def output_name(pattern, obj=None, frame=None):
    """The file name for source object ``obj`` (a name) and ``frame`` from an output ``pattern``."""
    name = pattern
    if obj is not None:
        name = name.replace("{object}", bpy.path.clean_name(obj))
    if frame is not None:
        name = name.replace("{frame}", str(frame))
        name = _HASHES.sub(lambda m: f"{frame:0{len(m.group())}d}", name)
    return name


def per_frame(pattern):
    return "{frame}" in pattern or "#" in os.path.basename(pattern)


def remove_stale_partials(folder):
    """Remove the partial outputs in ``folder`` that a killed task of this machine left (its process is gone)."""
    host = _host()
    for path in glob.glob(os.path.join(glob.escape(folder), ".*.tessera-partial-*")):
        m = _PARTIAL.match(os.path.basename(path))
        if m and m.group("host") == host and not render_jobs.is_alive(int(m.group("pid"))):
            if os.path.isdir(path):
                shutil.rmtree(path, ignore_errors=True)
            else:
                try:
                    os.remove(path)
                except OSError:
                    pass


def _host():
    return re.sub(r"[^A-Za-z0-9]", "", socket.gethostname())[:32] or "host"


def _partial(path):
    folder, base = os.path.split(path)
    stem, ext = os.path.splitext(base)
    return os.path.join(folder, f".{stem}.tessera-partial-{_host()}-{os.getpid()}{ext}")




def failed(path, cause):
    """The `WriteFailed` of ``path``: "PATH: not written: CAUSE"."""
    return WriteFailed(f"{path}: not written: {cause}")


def _writable(folder):
    """None when files can be made in the existing folder ``folder``, else why not."""
    if os.access(folder, os.W_OK):
        return None
    try:
        if os.statvfs(folder).f_flag & os.ST_RDONLY:
            return written.CAUSES[errno.EROFS]
    except (OSError, AttributeError):
        pass
    return written.CAUSES[errno.EACCES]


def _nearest_existing(folder):
    """``folder``, or the nearest folder above it that exists (what a write there will be made in)."""
    while not os.path.lexists(folder) and os.path.dirname(folder) != folder:
        folder = os.path.dirname(folder)
    return folder


def probe_output(path):
    """Raise `WriteFailed` when ``path`` cannot be written: it is a folder, a folder on its way is a file, or its
    folder (or the nearest one that exists) is read-only or not ours. Checked before any work, and again at the
    write."""
    path = os.path.abspath(path)
    if os.path.isdir(path):
        raise failed(path, written.CAUSES[errno.EISDIR])
    folder = _nearest_existing(os.path.dirname(path))
    if not os.path.isdir(folder):
        raise failed(path, f"{folder} is a file, not a folder")
    why = _writable(folder)
    if why:
        raise failed(path, f"{why} ({folder})")


@dataclass
class Pending:
    """A file written whole under a partial name: `commit` gives it its final name(s), `discard` removes it.
    ``moves``: [(partial path, final path)], the main file last; ``partial``: what to remove (a file or folder)."""

    moves: list
    partial: str

    @property
    def paths(self):
        return [final for _, final in self.moves]

    def commit(self):
        for src, dst in self.moves:
            os.replace(src, dst)
        self.discard()
        return self.paths

    def discard(self):
        if os.path.isdir(self.partial):
            shutil.rmtree(self.partial, ignore_errors=True)
        elif os.path.lexists(self.partial):
            os.remove(self.partial)


class Outputs:
    """The files of one run: each written and checked under a partial name (`write`, `write_with`), all given their
    final names together at the end (`commit`), or all removed (`discard`): a run writes every output or none."""

    def __init__(self):
        self.pending = []

    def write(self, path, objects):
        """Write ``objects`` to ``path`` (format by extension; a .blend holds the whole scene): the final paths."""
        ext = extension(path)
        if ext == ".blend":
            return self.write_with(path, lambda p: bpy.ops.wm.save_as_mainfile(filepath=p, copy=True,
                                                                              check_existing=False))
        counts = _mesh_counts(objects)
        _check_space(path, counts, ext)
        return self.write_with(path, lambda p: _export(p, objects, ext), _expected(objects, counts, ext))

    def write_with(self, path, writer, expected=None):
        """Call ``writer(partial path)`` to write ``path`` (`write_with`): the final paths."""
        pending = write_with(path, writer, expected)
        self.pending.append(pending)
        return pending.paths

    def commit(self):
        done = []
        while self.pending:
            done += self.pending.pop(0).commit()
        return done

    def discard(self):
        while self.pending:
            self.pending.pop().discard()


#: Formats whose exporter may end the process when the disk fills (Alembic's library aborts): refused unless the
#: free space is this many times the size `written.least_size` gives.
_ABORTS_WHEN_FULL = {".abc": 1.25}


def _check_space(path, counts, ext):
    """Refuse, before the exporter runs, an output that cannot fit: the file system has less free space than the least
    its meshes take (``counts``: `_mesh_counts`; `written.least_size`; more for formats whose exporter aborts on a
    full disk)."""
    free = written.free_bytes(_nearest_existing(os.path.dirname(os.path.abspath(path))))
    if free is None:
        return
    need = sum(written.least_size(ext, v, c, f) for v, c, f in counts) * _ABORTS_WHEN_FULL.get(ext, 1.0)
    if need > free:
        raise failed(os.path.abspath(path), f"{written.CAUSES[errno.ENOSPC]} (it needs at least {_megabytes(need)}; "
                                            f"{_megabytes(free)} free)")


def _mesh_counts(objects):
    """(vertices, face corners, faces) of each mesh object of ``objects``, evaluated (as exporters write them)."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    meshes = [ob.evaluated_get(depsgraph).data for ob in objects if ob.type == "MESH"]
    return [(len(m.vertices), len(m.loops), len(m.polygons)) for m in meshes]


def _megabytes(n):
    return f"{n / 1e6:.1f} MB" if n >= 1e5 else f"{n / 1e3:.0f} kB"


def _expected(objects, counts, ext):
    """What an OBJ of ``objects`` holds ({"vertices", "faces"}; ``counts``: `_mesh_counts`), when every one is a
    mesh; else None."""
    if ext != ".obj" or not objects or len(counts) != len(objects):
        return None
    return {"vertices": sum(v for v, _, _ in counts), "faces": sum(f for _, _, f in counts)}


def write_with(path, writer, expected=None):
    """Call ``writer(temporary path)`` to write ``path``, check the file whole (`written.check_written`), and return
    the `Pending` that renames it: the file at ``path`` is complete or absent. Formats that name files beside them
    (`_SIDECARS`) are written under their final names in a folder of their own, moved at the commit, the main file
    last. Every failure is a `WriteFailed` naming the path and the cause (a stop while the writer runs: `Stopped`)."""
    path = os.path.abspath(path)
    probe_output(path)
    folder = os.path.dirname(path)
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError as err:
        raise failed(path, written.os_cause(err)) from None
    remove_stale_partials(folder)
    ext = extension(path)
    sidecars = ext in _SIDECARS
    partial = _partial(path)[: -len(ext)] if sidecars else _partial(path)
    main = os.path.join(partial, os.path.basename(path)) if sidecars else partial
    pending = Pending([], partial)
    try:
        if sidecars:
            os.makedirs(partial, exist_ok=True)
        _run_writer(path, writer, main)
        if not os.path.isfile(main):
            raise failed(path, "the exporter wrote nothing")
        try:
            written.check_written(main, expected)
        except written.ShortWrite as err:
            raise failed(path, written.CAUSES[errno.ENOSPC] if written.disk_full(folder) else str(err)) from None
        except OSError as err:
            raise failed(path, written.os_cause(err)) from None
        if sidecars:
            names = sorted(os.listdir(partial), key=lambda n: n == os.path.basename(path))  # the main file last
            pending.moves = [(os.path.join(partial, n), os.path.join(folder, n)) for n in names]
        else:
            pending.moves = [(partial, path)]
        return pending
    except BaseException:
        pending.discard()
        raise


def _run_writer(path, writer, target):
    """``writer(target)`` with its output held back: on failure one sentence (`WriteFailed`), not the exporter's
    traceback; on success what it printed is passed on."""
    with _captured_output() as captured:
        try:
            writer(target)
            error = None
        except OSError as err:
            error = written.os_cause(err)
        except RuntimeError as err:  # the exporter's report, or its Python exception
            error = str(err)
    if error is None:
        cause = written.cause_in_text(captured.text)
        if cause is None:
            captured.replay()
            return
        raise failed(path, cause)  # the exporter printed an operating-system error but reported nothing (USD)
    if stopping.requested:
        raise stopping.Stopped(stopping.message())
    cause = written.cause_in_text(error + captured.text)
    if cause is None and written.disk_full(os.path.dirname(path)):
        cause = written.CAUSES[errno.ENOSPC]
    if cause is None:  # the writer's own words hide the cause (Blender 4.x's .blend writer says "No such file…")
        need, free = _needed_bytes(writer, os.path.basename(target)), written.free_bytes(os.path.dirname(path))
        if need is not None and free is not None and need > free:
            cause = f"{written.CAUSES[errno.ENOSPC]} (it needs {_megabytes(need)}; {_megabytes(free)} free)"
    if cause is None:
        lines = [ln.strip() for ln in error.splitlines() if ln.strip() and not ln.startswith((" ", "Traceback"))]
        cause = (lines[-1] if lines else "the exporter failed").removeprefix("Error: ")
    raise failed(path, cause)


def _needed_bytes(writer, name):
    """The bytes ``writer`` writes for a file called ``name``, learnt by writing it into memory (a tmpfs,
    ``/dev/shm``), to tell a full disk behind a writer's unclear failure; None where that cannot be learnt."""
    import tempfile

    if not os.path.isdir("/dev/shm"):
        return None
    try:
        folder = tempfile.mkdtemp(prefix="tessera-size-", dir="/dev/shm")
    except OSError:
        return None
    try:
        with _captured_output():
            writer(os.path.join(folder, name))
        return sum(os.path.getsize(os.path.join(folder, n)) for n in os.listdir(folder))
    except (OSError, RuntimeError):  # it fails in memory too (or memory is short): nothing learnt
        return None
    finally:
        shutil.rmtree(folder, ignore_errors=True)


class _Captured:
    """What a writer printed: ``streams`` {fd: text}."""

    def __init__(self):
        self.streams = {}

    @property
    def text(self):
        return "".join(self.streams.values())

    def replay(self):
        for fd, stream in ((1, sys.stdout), (2, sys.stderr)):
            if self.streams.get(fd):
                stream.write(self.streams[fd])
                stream.flush()


def _flush_all():
    """Flush Python's and C's buffered output (Blender prints its reports and log with C's stdio)."""
    sys.stdout.flush()
    sys.stderr.flush()
    try:
        import ctypes

        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError, TypeError):  # no C library to call (Windows): Python's flush is all
        pass


@contextmanager
def _captured_output():
    """File descriptors 1 and 2 into memory (memfds, never the disk that may be full) while the block runs: Blender
    prints an operator's failure (an exporter's traceback) on them."""
    captured = _Captured()
    try:
        held = {fd: os.memfd_create(f"tessera-{fd}") for fd in (1, 2)}
    except (AttributeError, OSError):  # not Linux: nothing is held back
        yield captured
        return
    _flush_all()
    saved = {fd: os.dup(fd) for fd in held}
    for fd, memfd in held.items():
        os.dup2(memfd, fd)
    try:
        yield captured
    finally:
        _flush_all()
        for fd, memfd in held.items():
            os.dup2(saved[fd], fd)
            os.close(saved[fd])
            os.lseek(memfd, 0, os.SEEK_SET)
            with os.fdopen(memfd, "rb") as f:
                captured.streams[fd] = f.read().decode("utf-8", "replace")


def _export(path, objects, ext):
    op, kw = EXPORTERS[ext]
    select_only(objects)
    _operator(op)(filepath=path, **kw)


def select_only(objects):
    """Make ``objects`` the selection (the first active), in the current view layer."""
    layer = bpy.context.view_layer
    for ob in layer.objects:
        ob.select_set(False)
    for ob in objects:
        ob.select_set(True)
    layer.objects.active = objects[0] if objects else None

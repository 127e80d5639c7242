"""Tessera's node groups as an asset library: a .blend of every group (marked as assets, in catalogs under
*Tessera*) written into the extension's user folder, and a preferences asset library entry "Tessera" pointing at
it, added on enable and removed on disable (one entry, never a stale one). The groups then show in Add Modifier
and in the node editor's Add menu; a file that uses one holds its own copy (appended), so it evaluates on a
machine without the add-on.

The .blend is named by a hash of the groups' names and versions and of the Blender that builds them: a new version
writes a new file and removes the old one. ``make build`` ships one in the zip (``node_library/``, built by the
build's Blender, see tools/build_extension.py); the entry points there when it was built for this Blender, and
otherwise the add-on writes its own into the user folder: with a window, a worker Blender writes it (building the
groups takes a second or two, which would hold the window) and the entry is added when it is done; in background mode,
the add-on itself. Nothing is started while Blender is starting (data is read-only then): a one-shot timer does it.
"""

import hashlib
import uuid
from pathlib import Path

import bpy

from ..kernels.common.errors import TesseraError
from . import node_groups
from .displacement import nodes as _displace_nodes  # noqa: F401 (registers its group)
from .manifest import license_id, manifest
from .preferences import BASE_PACKAGE
from .terrain import nodes as _terrain_nodes  # noqa: F401 (registers its group)
from .tessellation import phong_nodes as _phong_nodes  # noqa: F401 (registers its group)
from .tessellation import pn_nodes as _pn_nodes  # noqa: F401 (registers its group)
from .tubes import nodes as _tube_nodes  # noqa: F401 (registers its group)

LIBRARY_NAME = "Tessera"
CATALOG_FILE = "blender_assets.cats.txt"
_NAMESPACE = uuid.UUID("6f1c8f0e-3b1e-4c43-9a55-7e2a1d0c5b21")


#: Where the built extension keeps its shipped library (tools/build_extension.py writes it).
SHIPPED_DIR = Path(__file__).resolve().parents[1] / "node_library"


def library_dir():
    """The folder of the library (created), or None where Tessera runs as a legacy add-on."""
    try:
        return Path(bpy.utils.extension_path_user(BASE_PACKAGE, path="node_library", create=True))
    except (ValueError, AttributeError):
        return None


def _available():
    return [s for s in node_groups.GROUPS.values() if s.available is None or s.available() is None]


def library_file(directory):
    key = ";".join(f"{s.name}:{s.version}" for s in sorted(_available(), key=lambda s: s.name))
    key += ";blender:{}.{}".format(*bpy.app.version[:2])  # a group built by another Blender may differ
    return Path(directory) / f"tessera_nodes_{hashlib.sha256(key.encode()).hexdigest()[:12]}.blend"


def catalog_id(path):
    return str(uuid.uuid5(_NAMESPACE, path))


def describe_asset(asset_data, spec):
    """Fill a group's asset metadata: its description, and the extension's author, license and copyright."""
    asset_data.description = spec.description
    asset_data.author = manifest().get("maintainer", "")
    asset_data.license = license_id()
    asset_data.copyright = ", ".join(manifest().get("copyright", []))


def write_library(directory):
    """Write the groups' .blend and the catalogs into ``directory`` (older Tessera .blends removed). Returns the
    file. Groups this file already had are left as they were; the ones built for writing are removed again."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    path = library_file(directory)
    specs = _available()
    before = set(bpy.data.node_groups)
    trees = [node_groups.ensure_group(spec) for spec in specs]
    try:
        for spec, tree in zip(specs, trees, strict=True):
            tree.asset_mark()
            tree.asset_data.catalog_id = catalog_id(spec.catalog)
            describe_asset(tree.asset_data, spec)
        tmp = path.with_suffix(".tmp.blend")
        bpy.data.libraries.write(str(tmp), set(trees), fake_user=True, compress=True)
        tmp.replace(path)  # never a half-written library
    finally:
        for tree in trees:
            if tree in before:
                tree.asset_clear()
            else:
                bpy.data.node_groups.remove(tree)
    catalogs = sorted({s.catalog for s in specs} | {"Tessera"})
    built = "Blender {}.{}".format(*bpy.app.version[:2])
    lines = [f"# Tessera's node-group catalogs (written by the add-on, {built})", "VERSION 1", ""]
    lines += [f"{catalog_id(c)}:{c}:{c.replace('/', '-')}" for c in catalogs]
    (directory / CATALOG_FILE).write_text("\n".join(lines) + "\n", encoding="utf-8")
    for old in directory.glob("tessera_nodes_*.blend"):
        if old != path:
            old.unlink()
    return path


def _entries():
    return [lib for lib in bpy.context.preferences.filepaths.asset_libraries if lib.name == LIBRARY_NAME]


def _complete(directory):
    return library_file(directory).exists() and (directory / CATALOG_FILE).exists()


def _point_entry(directory):
    """The one "Tessera" asset library entry, pointing at ``directory``."""
    libraries = bpy.context.preferences.filepaths.asset_libraries
    entries = _entries()
    for extra in entries[1:]:
        libraries.remove(extra)
    if entries:
        entries[0].path = str(directory)
    else:
        libraries.new(name=LIBRARY_NAME, directory=str(directory))


def register_library():
    """Add (or repoint) the one "Tessera" asset library: the shipped library where it was built for this Blender,
    else the user folder's, written if it is missing or outdated: with a window, by a worker Blender
    (`node_library_worker.py`; the entry is added when it is done, `_poll_writer`), so the window is never held;
    in background mode, here."""
    directory = SHIPPED_DIR if _complete(SHIPPED_DIR) else library_dir()
    if directory is None:
        return None
    if not _complete(directory):
        if not bpy.app.background and _start_writer(directory):
            return directory
        write_library(directory)
    _point_entry(directory)
    return directory


_writer = {}  # "job": the RenderJob writing the library, "directory": where


def _start_writer(directory):
    """Start a worker Blender writing the library into ``directory``; False when it cannot start (then the caller
    writes it here)."""
    import json

    from . import render_jobs

    folder = render_jobs.job_folder("library")
    try:
        job_file = Path(folder) / "job.json"
        job_file.write_text(json.dumps({"package": str(Path(__file__).resolve().parents[1]),
                                        "directory": str(directory)}), encoding="utf-8")
        log = Path(folder) / "worker.log"
        process = render_jobs.start_worker(Path(__file__).with_name("node_library_worker.py"), job_file, log)
    except OSError as err:
        render_jobs.remove_folder(folder)
        print(f"Tessera: could not start a Blender to write the node-group library ({err}); writing it here")
        return False
    _writer.update(job=render_jobs.RenderJob(process, folder, 1, str(log)), directory=directory)
    if not bpy.app.timers.is_registered(_poll_writer):
        bpy.app.timers.register(_poll_writer, first_interval=0.25, persistent=True)
    return True


def _poll_writer():
    """While the worker writes the library: wait; once it ends, add the entry (or, when it failed, say why once and
    write the library here: the groups are then in Add Modifier as before)."""
    job = _writer.get("job")
    if job is None:
        return None
    if job.running():
        return 0.25
    directory = _writer.pop("directory")
    _writer.pop("job")
    try:
        job.check("Writing the node-group library")
    except TesseraError as err:  # the worker's failure, in its words
        print(f"Tessera: {err}; writing it here")
    finally:
        job.close()
    try:
        if not _complete(directory):
            write_library(directory)
        _point_entry(directory)
    except (OSError, RuntimeError) as err:
        print(f"Tessera: the node-group library could not be written to {directory} ({err}); the groups are in "
              "Object › Tessera › Add Tessera Node Group")
    return None


def _deferred():
    register_library()
    return None  # do not repeat


def register():
    try:
        register_library()
    except AttributeError:  # bpy.data is read-only while Blender starts: write it once it has started
        bpy.app.timers.register(_deferred, first_interval=0.1)


def unregister():
    for timer in (_deferred, _poll_writer):
        if bpy.app.timers.is_registered(timer):
            bpy.app.timers.unregister(timer)
    job = _writer.pop("job", None)
    _writer.clear()
    if job is not None:
        job.cancel()
    libraries = bpy.context.preferences.filepaths.asset_libraries
    for entry in _entries():
        libraries.remove(entry)

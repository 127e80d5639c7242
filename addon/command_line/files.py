"""Files in and out of the command line: scenes and meshes read through Blender's importers, results written through
Blender's exporters under a temporary name and renamed when complete, so a task that is killed never leaves a half
file under the name asked for.

Output names may hold ``{object}`` (one file per source object) and ``{frame}`` or ``#``s (one per frame, the ``#``s
giving the zero-padded width, as Blender's render output does).
"""

import glob
import os
import re
import shutil
import socket

import bpy

from .. import render_jobs

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


def extension(path):
    return os.path.splitext(path)[1].lower()


def check_output(path, allowed=None):
    """Refuse an output whose format Blender cannot write here (or, with ``allowed``, this verb cannot)."""
    ext = extension(path)
    known = set(EXPORTERS) | {".blend"} if allowed is None else set(allowed)
    if ext not in known:
        raise FileProblem(f"{path}: cannot write {ext or 'a file without an extension'}; use one of "
                          f"{', '.join(sorted(known))}")


def _operator(path):
    module, name = path.split(".")
    addon = _IO_ADDONS.get(path)
    if addon is not None:
        import addon_utils

        if not addon_utils.check(addon)[1]:
            addon_utils.enable(addon, default_set=False)
    return getattr(getattr(bpy.ops, module), name)


def read_inputs(paths):
    """Open the scene and import the meshes named by ``paths``: a .blend is opened (at most one, first); other files
    are imported into it, or into an empty scene when no .blend is given. Returns the objects the imports added."""
    paths = [os.path.abspath(p) for p in paths]
    for p in paths:
        if not os.path.isfile(p):
            raise FileProblem(f"{p}: no such file")
        if extension(p) != ".blend" and extension(p) not in IMPORTERS:
            raise FileProblem(f"{p}: cannot read {extension(p) or 'a file without an extension'}; give a .blend or "
                              f"one of {', '.join(sorted(IMPORTERS))}")
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


def write(path, objects):
    """Write ``objects`` to ``path`` (format by extension; a .blend holds the whole scene, the objects in it) through
    `write_with`. Returns the paths written."""
    ext = extension(path)
    if ext == ".blend":
        return write_with(path, lambda p: bpy.ops.wm.save_as_mainfile(filepath=p, copy=True, check_existing=False))
    return write_with(path, lambda p: _export(p, objects, ext))


def write_with(path, writer):
    """Call ``writer(temporary path)`` to write the file, then rename it to ``path``: the file at ``path`` is complete
    or absent. Formats that name files beside them (`_SIDECARS`) are written under their final names in a folder of
    their own, then moved, the main file last. Returns the paths written."""
    path = os.path.abspath(path)
    folder = os.path.dirname(path)
    os.makedirs(folder, exist_ok=True)
    remove_stale_partials(folder)
    ext = extension(path)
    if ext in _SIDECARS:
        partial = _partial(path)[: -len(ext)]
        os.makedirs(partial, exist_ok=True)
        try:
            writer(os.path.join(partial, os.path.basename(path)))
            written = []
            names = sorted(os.listdir(partial), key=lambda n: n == os.path.basename(path))  # the main file last
            for name in names:
                os.replace(os.path.join(partial, name), os.path.join(folder, name))
                written.append(os.path.join(folder, name))
            return written
        finally:
            shutil.rmtree(partial, ignore_errors=True)
    partial = _partial(path)
    try:
        writer(partial)
        if not os.path.isfile(partial):
            raise FileProblem(f"{path}: the exporter wrote nothing")
        os.replace(partial, path)
    finally:
        if os.path.exists(partial):
            os.remove(partial)
    return [path]


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

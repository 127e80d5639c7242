"""Helpers shared by the blender-tier tests (importable as ``blender_helpers``, like ``mesh_checks``)."""

import importlib
import os
import time

import pytest
from conftest import ADDON_MODULE


def select_only(bpy, *obs):
    """Select exactly ``obs`` and make the first one active (what a click and shift-clicks leave)."""
    for other in bpy.context.selected_objects:
        other.select_set(False)
    for ob in obs:
        ob.select_set(True)
    bpy.context.view_layer.objects.active = obs[0]


def compat():
    """The enabled add-on's `addon.compat` (what differs between Blender versions)."""
    return importlib.import_module(f"{ADDON_MODULE}.addon.compat")


def refuses_tangent_space(bpy, size=32):
    """On a Blender without the UV Tangent node, a tangent-space map is refused with the version it needs and
    nothing is made."""
    message = compat().UV_TANGENT_MESSAGE
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=4, y_subdivisions=4, size=2)
    images = len(bpy.data.images)
    with pytest.raises(RuntimeError) as err:
        bpy.ops.tessera.displacement_add(width=size, height=size, mode="VECTOR", space="TANGENT")
    assert message in str(err.value)
    assert len(bpy.data.images) == images and not bpy.context.active_object.modifiers


def stroke_elements(points, map_space=True):
    """Stroke elements for ``tessera.displacement_stroke`` from map texels (x, y, pressure) or surface points
    (x, y, z), each with every field this Blender's stroke element needs."""
    element = compat().stroke_element
    return [element(p[:3] if not map_space else (p[0], p[1], 0.0), p[2] if map_space else 1.0, first=i == 0)
            for i, p in enumerate(points)]


class UiOperator:
    """An operator as the UI runs it: its settings, its methods bound to it, its reports kept; ``drive`` calls its
    ``modal`` with timer events (or Esc) as Blender's event loop does, without a window (none exists here)."""

    def __init__(self, bpy, idname, **settings):
        module, name = idname.split(".")
        op = getattr(getattr(bpy.ops, module), name)
        self.bl_rna = op.get_rna_type()
        self.cls = getattr(bpy.types, op.idname())
        for p in self.bl_rna.properties:
            if p.identifier != "rna_type":
                setattr(self, p.identifier, settings.get(p.identifier, getattr(p, "default", None)))
        self.reports, self._timer = [], None
        for klass in reversed(self.cls.__mro__):  # the operator's own methods (modal, _begin, _finish, ...), bound here
            for attr, fn in vars(klass).items():
                if callable(fn) and (attr == "modal" or (attr.startswith("_") and not attr.startswith("__"))):
                    setattr(self, attr, fn.__get__(self))
                elif not callable(fn) and not attr.startswith("__") and not hasattr(self, attr):
                    setattr(self, attr, fn)  # its class constants (the status bar's words, the last render kept)

    def report(self, kind, text):
        self.reports.append((set(kind), text))

    def drive(self, context, escape_after=None, timeout=300, until=None):
        """Timer events (Esc after ``escape_after`` ticks) until the operator ends: its result; or None as soon as
        ``until()`` is true."""
        class UI:  # the real context, with a window's status bar and timers that need no window
            window_manager = type("WM", (), {"event_timer_remove": staticmethod(lambda t: None),
                                             "progress_update": staticmethod(lambda v: None),
                                             "progress_end": staticmethod(lambda: None)})()
            workspace = type("WS", (), {"status_text_set": staticmethod(lambda t: None)})()

            def __getattr__(self, name):
                return getattr(context, name)

        ui = UI()
        start, ticks = time.monotonic(), 0
        while time.monotonic() - start < timeout:
            if until is not None and until():
                return None
            ticks += 1
            kind = "ESC" if escape_after is not None and ticks > escape_after else "TIMER"
            result = self.modal(ui, type("Event", (), {"type": kind})())
            if result != {"RUNNING_MODAL"}:
                return result
            time.sleep(0.05)
        raise AssertionError("the job did not end")


def blender_on_path(folder):
    """A ``blender`` command in ``folder``/bin that runs `blender_cli.py` (the ``bpy`` module standing in for the
    Blender executable these machines do not have): the environment with it first on PATH (a copy of os.environ)."""
    import os
    import stat
    import sys
    from pathlib import Path

    bin_dir = Path(folder) / "bin"
    bin_dir.mkdir(exist_ok=True)
    shim = bin_dir / "blender"
    cli = Path(__file__).resolve().parent / "blender_cli.py"
    shim.write_text(f'#!/bin/sh\nexec "{sys.executable}" "{cli}" "$@"\n')
    shim.chmod(shim.stat().st_mode | stat.S_IEXEC)
    return dict(os.environ, PATH=f"{bin_dir}{os.pathsep}{os.environ['PATH']}")


def packaged_blender_root():
    """The chroot with Debian's packaged Blender (tools/window_setup.sh makes it once per machine), when the command
    line's tests are to run it: as root, with unshare and chroot, unless TESSERA_CLI_BLENDER=standin (`make test-all`
    runs the stand-in on each ``bpy`` version). None where the stand-in runs."""
    import os
    import shutil
    import subprocess
    from pathlib import Path

    if os.environ.get("TESSERA_CLI_BLENDER") == "standin" or os.geteuid() != 0:
        return None
    if shutil.which("unshare") is None or shutil.which("chroot") is None:
        return None
    root = Path(__file__).resolve().parents[1]
    done = subprocess.run(["bash", str(root / "tools" / "window_setup.sh")], capture_output=True, text=True)
    if done.returncode != 0:
        pytest.fail(f"the packaged Blender could not be set up: {done.stderr.strip()[-2000:]}", pytrace=False)
    return Path(done.stdout.strip().splitlines()[-1])


def packaged_blender_on_path(folder, binds, passed=("BLENDER_USER_RESOURCES", "TMPDIR")):
    """A ``blender`` command in ``folder``/bin that runs Debian's packaged Blender (tools/packaged_run.sh) in the
    caller's folder, with the folders ``binds`` (and what is mounted below them) at their own paths and the
    variables ``passed`` passed in; a signal sent to it reaches Blender itself. The environment with it first on
    PATH (a copy of os.environ)."""
    import os
    import shlex
    import stat
    from pathlib import Path

    bin_dir = Path(folder) / "bin"
    bin_dir.mkdir(exist_ok=True)
    run = Path(__file__).resolve().parents[1] / "tools" / "packaged_run.sh"
    out = Path(folder) / "packaged_out"
    out.mkdir(exist_ok=True)
    bind_args = " ".join(f"--bind {shlex.quote(str(b))}" for b in binds)
    env_args = " ".join(f'${{{name}:+--env {name}="${name}"}}' for name in passed)
    shim = bin_dir / "blender"
    shim.write_text(f'#!/bin/bash\nexec bash {shlex.quote(str(run))} {bind_args} {env_args} --cd "$PWD" '
                    f'{shlex.quote(str(out))} 0 -- blender "$@"\n')
    shim.chmod(shim.stat().st_mode | stat.S_IEXEC)
    return dict(os.environ, PATH=f"{bin_dir}{os.pathsep}{os.environ['PATH']}")


def cli_blender_on_path(folder, binds):
    """``blender`` on PATH for the command line's tests: the packaged Blender where it runs here
    (`packaged_blender_root`), else the stand-in (`blender_on_path`). (environment, whether it is the packaged)."""
    if packaged_blender_root() is not None:
        return packaged_blender_on_path(folder, binds), True
    return blender_on_path(folder), False


def installed_blender(built_zips, home, binds=()):
    """``run(*args, timeout=600)``: ``blender ARGS`` in a process (cwd ``home``), with Tessera installed from the built
    zip into a user folder of its own (`cli_blender_on_path`; ``binds``: the folders its files are in, besides
    ``home`` and the zip's): CompletedProcess. ``run.start(*args)`` starts one (Popen); ``run.env`` is its
    environment; ``run.packaged`` whether it is Debian's packaged Blender."""
    import subprocess

    linux = next(z for z in built_zips if z.name.endswith("linux_x64.zip"))
    env, packaged = cli_blender_on_path(home, [home, linux.parent, *binds])
    env = dict(env, BLENDER_USER_RESOURCES=str(home / "user"))
    env.pop("PYTHONPATH", None)

    def run(*args, timeout=600):
        return subprocess.run(["blender", *map(str, args)], env=env, capture_output=True, text=True, timeout=timeout,
                              cwd=home)

    def start(*args):
        return subprocess.Popen(["blender", *map(str, args)], env=env, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True, cwd=home)

    done = run("--command", "extension", "install-file", "-r", "user_default", "-e", linux)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    run.start, run.env, run.packaged = start, env, packaged
    return run


def processes_naming(text):
    """The ids of the running processes whose command line holds ``text`` (one that ends while /proc is read is
    passed over)."""
    found = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                if text.encode() in f.read():
                    found.append(int(pid))
        except OSError:  # it ended meanwhile
            pass
    return found

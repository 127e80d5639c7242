"""The ``blender`` command line, run by the ``bpy`` module, for the README's shell snippets: the machines that test
Tessera have the ``bpy`` wheel of each supported Blender but no Blender executable.

Handled, in Blender's own order (arguments act as they come): ``-b``/``--background``, ``--factory-startup``,
``--command``/``-c extension ...`` (Blender's own extension command-line handler, as ``blender -c extension`` runs it),
``-c ID ...`` for a command an enabled add-on registered (``blender -c tessera ...``),
a ``.blend`` to open, ``--python FILE``, ``-o``/``--render-output``, ``-E``/``--engine``, ``-f``/``--render-frame``
and ``-a``/``--render-anim``. As Blender does at startup, the user's preferences are loaded and the add-ons they
enable are enabled (unless ``--factory-startup``; on 4.2, whose module cannot reload preferences, the extensions
installed in the user's repositories are enabled instead). Anything else is refused, so a snippet that uses an
option this stand-in does not know fails instead of passing unchecked.

Usage: python tests/blender_cli.py ARGS...   (the test puts a ``blender`` script that runs this first on PATH)
"""

import os
import runpy
import sys
from pathlib import Path


def _startup(factory):
    """Load the user's preferences and enable the add-ons they enable, as Blender's startup does."""
    import addon_utils
    import bpy

    if factory:
        return
    if bpy.app.version >= (4, 5, 0):
        bpy.ops.wm.read_userpref()
        addon_utils.reset_all()
        return
    # Blender 4.2's bpy module crashes in wm.read_userpref: enable the extensions installed in the user's
    # repositories instead (what an install with -e, as the README's, enabled)
    for repo in bpy.context.preferences.extensions.repos:
        folder = Path(repo.directory) if repo.enabled else None
        if folder is None or not folder.is_dir():
            continue
        for package in sorted(folder.iterdir()):
            if (package / "blender_manifest.toml").exists():
                addon_utils.enable(f"bl_ext.{repo.module}.{package.name}", default_set=True)


def _render(frames):
    import bpy

    scene = bpy.context.scene
    for frame in frames:
        scene.frame_set(frame)
        path = scene.render.frame_path(frame=frame)
        scene.render.filepath, kept = path, scene.render.filepath
        try:
            bpy.ops.render.render(write_still=True)
        finally:
            scene.render.filepath = kept
        print(f"Saved: '{path}'")


def _command(name, args):
    """``-c NAME ARGS``: an add-on's registered command, run after startup (Blender's ``bpy.utils.register_cli_command``
    registry, recorded here as the enabled add-ons register into it). Exit code 1 when no add-on registered it."""
    import bpy

    commands = {}
    register = bpy.utils.register_cli_command

    def recording(command_id, execute):
        commands[command_id] = execute
        return register(command_id, execute)

    bpy.utils.register_cli_command = recording
    try:
        _startup(False)
    finally:
        bpy.utils.register_cli_command = register
    if name not in commands:
        print(f"Error: command {name!r} not found", file=sys.stderr)
        return 1
    return commands[name](args)


def main(argv):
    if argv[:1] in (["--command"], ["-c"]):
        if argv[1:2] != ["extension"]:
            return _command(argv[1], argv[2:])
        import bpy  # noqa: F401 (bl_pkg needs Blender's modules)
        from bl_pkg import bl_extension_cli

        return bl_extension_cli.cli_extension_handler(argv[2:])
    import bpy

    _startup("--factory-startup" in argv)
    i = 0
    while i < len(argv):
        arg = argv[i]
        if arg in ("-b", "--background", "--factory-startup"):
            i += 1
        elif arg.endswith(".blend"):
            bpy.ops.wm.open_mainfile(filepath=os.path.abspath(arg), load_ui=False)
            i += 1
        elif arg in ("--python", "-P"):
            runpy.run_path(os.path.abspath(argv[i + 1]), run_name="__main__")
            i += 2
        elif arg in ("-o", "--render-output"):
            bpy.context.scene.render.filepath = argv[i + 1]
            i += 2
        elif arg in ("-E", "--engine"):
            bpy.context.scene.render.engine = argv[i + 1]
            i += 2
        elif arg in ("-f", "--render-frame"):
            _render([int(f) for f in argv[i + 1].split(",")])
            i += 2
        elif arg in ("-a", "--render-anim"):
            scene = bpy.context.scene
            _render(range(scene.frame_start, scene.frame_end + 1, scene.frame_step))
            i += 1
        else:
            raise SystemExit(f"blender_cli: the stand-in does not know the argument {arg!r}")
    return 0


if __name__ == "__main__":
    code = main(sys.argv[1:])
    if sys.argv[1:2] in (["--command"], ["-c"]):
        # Blender ends a command with its own exit (the command's code, no Python teardown). The bpy module of 4.2,
        # torn down by Python, crashes after a glTF export (its file-browser panels are freed after Python: a
        # segfault in bpy_class_free, exit 139), which Blender itself does not do: end as Blender does.
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(int(code or 0))
    sys.exit(code)

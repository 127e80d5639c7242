"""The source tree as the package ``tessera`` and as a Blender extension: the one bootstrap of the tests, benches,
tools, the demo and the window tier (none of it ships in the zip; standard library only).

Import it before ``tessera`` is importable: from a script in ``tools/`` as ``source_tree`` (its folder is first on
``sys.path``), from the repository root as ``tools.source_tree``, from anywhere else after putting the root on
``sys.path``.
"""

import sys
import tempfile
from pathlib import Path

#: The repository root: the add-on's package.
ROOT = Path(__file__).resolve().parents[1]


def as_package(prefix="tessera-", root=ROOT, folder=None):
    """Make ``import tessera`` import the tree ``root``: a folder holding the link ``tessera`` -> the tree, put first
    on ``sys.path``. The folder is ``folder`` (made if missing; its owner removes it) or a new temporary folder removed
    once this process has ended (`temp_folders.remove_at_exit`: Blender writes its user folder there as it exits).
    Returns the folder, which also serves as an extension repository (`enable_extension`)."""
    made = folder is None
    folder = Path(tempfile.mkdtemp(prefix=prefix)) if made else Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "tessera").symlink_to(root, target_is_directory=True)
    sys.path.insert(0, str(folder))
    if made:
        from tessera.tools.temp_folders import remove_at_exit

        remove_at_exit(folder)
    return folder


def enable_extension(folder, repo):
    """Enable Tessera in the running Blender from ``folder`` (from `as_package`), registered as the local extension
    repository ``repo`` as Blender loads an extension: returns the add-on's package name ``bl_ext.<repo>.tessera``.
    Raises RuntimeError when the add-on does not enable."""
    import importlib

    bpy = importlib.import_module("bpy")  # first: Blender's own modules (addon_utils) are importable once bpy is
    addon_utils = importlib.import_module("addon_utils")
    repos = bpy.context.preferences.extensions.repos
    if repo not in {r.module for r in repos}:
        repos.new(name=repo, module=repo, custom_directory=str(folder), source="USER")
    name = f"bl_ext.{repo}.tessera"
    if addon_utils.enable(name, default_set=True, handle_error=None) is None:
        raise RuntimeError(f"the Tessera add-on failed to enable from {folder}")
    return name

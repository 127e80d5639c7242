"""Test tiers and isolation.

Tiers: unmarked kernel tests need numpy only; ``blender`` needs the ``bpy`` module, ``gpu`` a GPU
context (Mesa llvmpipe is enough), ``opencl`` pyopencl with a platform (PoCL). Outside CI a missing tier
is skipped with its reason; with ``CI=true`` a missing tier fails and any skip fails the run.

Blender's user folder and every cache go to a temporary folder, set before ``bpy`` is imported.
The source tree is importable as the package ``tessera`` through a symlink, which is also the dev
extension repository the ``blender`` tier enables the add-on from.
"""

import importlib
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from types import SimpleNamespace

import pytest

ROOT = Path(__file__).resolve().parents[1]
CI = os.environ.get("CI", "").strip().lower() in ("1", "true", "yes")
#: The GPU backend the gpu tier runs on: OPENGL (llvmpipe), or VULKAN (lavapipe, `tools/gpu_backend.py`).
GPU_BACKEND = os.environ.get("TESSERA_GPU_BACKEND", "OPENGL").strip().upper()
from tools.source_tree import as_package, enable_extension  # noqa: E402 (``python -m pytest``: the root is on the path)

_TMP = Path(tempfile.mkdtemp(prefix="tessera-tests-"))
REPO_DIR = as_package(folder=_TMP / "repo")  # holds the symlink "tessera" -> source tree
from tessera.tools.temp_folders import remove_at_exit  # noqa: E402

remove_at_exit(_TMP)  # nothing left in the temp folder, Blender's caches included
os.environ["BLENDER_USER_RESOURCES"] = str(_TMP / "blender_user")
os.environ["XDG_CACHE_HOME"] = str(_TMP / "cache")
os.environ["TESSERA_CACHE_DIR"] = str(_TMP / "cache" / "tessera")
DEV_REPO_MODULE = "tessera_dev"
ADDON_MODULE = f"bl_ext.{DEV_REPO_MODULE}.tessera"


def tier_unavailable(reason):
    """Skip (locally) or fail (CI) a test whose tier cannot run here."""
    if CI:
        pytest.fail(f"CI=true and a test tier is unavailable: {reason}", pytrace=False)
    pytest.skip(reason)


#: Job folders of background renders (`addon.render_jobs`) that were there before the tests: any other is a leftover.
_JOB_PREFIXES = ("tessera-impostor-", "tessera-board-", "tessera-bake-")
_JOB_FOLDERS_BEFORE = {n for n in os.listdir(tempfile.gettempdir()) if n.startswith(_JOB_PREFIXES)}


def pytest_sessionfinish(session, exitstatus):
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    left = sorted(n for n in os.listdir(tempfile.gettempdir())
                  if n.startswith(_JOB_PREFIXES) and n not in _JOB_FOLDERS_BEFORE)
    if left and session.exitstatus == 0:  # every job's folder goes when its result is read, on failure and on cancel
        if reporter:
            reporter.write_line(f"the tests left {len(left)} render-job folder(s) in the temp folder: {left[:5]}",
                                red=True)
        session.exitstatus = 1
    if not CI:
        return
    skipped = reporter.stats.get("skipped", []) if reporter else []
    if skipped and session.exitstatus == 0:
        reporter.write_line(f"CI=true: {len(skipped)} test(s) were skipped; every tier must run in CI", red=True)
        session.exitstatus = 1


@pytest.fixture
def numpy_reference():
    """Run a test on the numpy reference (OpenCL off), whatever the environment says; the OpenCL tests compare
    the OpenCL paths with it."""
    from tessera.kernels.common import opencl_runtime

    opencl_runtime.configure(mode="0")
    yield
    opencl_runtime.configure()


@pytest.fixture(scope="session")
def tmp_root():
    return _TMP


@pytest.fixture(scope="session")
def bpy_module():
    try:
        import bpy
    except ImportError as err:
        tier_unavailable(f"the bpy module is not installed ({err})")
    if GPU_BACKEND == "VULKAN":  # the gpu tier's Vulkan run: before any GPU context exists
        from tessera.tools.gpu_backend import use_vulkan

        try:
            use_vulkan()
        except RuntimeError as err:
            tier_unavailable(f"Vulkan cannot be selected: {err}")
    return bpy


@pytest.fixture(scope="session")
def addon(bpy_module):
    """The Tessera package as Blender loads it (dev extension repo on the source tree), enabled."""
    import addon_utils

    assert enable_extension(REPO_DIR, DEV_REPO_MODULE) == ADDON_MODULE
    yield sys.modules[ADDON_MODULE]
    addon_utils.disable(ADDON_MODULE, default_set=True)


@pytest.fixture(scope="session")
def addon_module(addon):
    """Import a submodule of the enabled add-on: ``addon_module("addon.bridge")``."""
    return lambda name: importlib.import_module(f"{ADDON_MODULE}.{name}")


@pytest.fixture
def clean_scene(bpy_module, addon):
    """An empty current scene; removes the objects, meshes, curves, materials, cameras and images the test left
    behind (an image another test made, such as a baked card, must not be taken for this test's)."""
    bpy = bpy_module

    def wipe():
        for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.curves, bpy.data.materials, bpy.data.cameras,
                           bpy.data.images):
            for item in list(collection):
                if getattr(item, "type", "IMAGE") == "IMAGE" or collection is not bpy.data.images:
                    collection.remove(item)  # Blender's own Render Result stays (it comes back by itself)

    wipe()
    yield bpy.context.scene
    wipe()


@pytest.fixture(scope="session")
def gpu_renderer(addon_module):
    """Create a GPU context (background mode) and return the renderer string."""
    errors = addon_module("kernels.common.errors")
    try:
        return addon_module("addon.gpu_context").ensure_gpu_context()
    except errors.GPUContextError as err:
        tier_unavailable(str(err))


@pytest.fixture(scope="session")
def opencl():
    """The OpenCL runtime (PoCL in CI), required."""
    from tessera.kernels.common import opencl_runtime
    from tessera.kernels.common.errors import OpenCLUnavailableError

    opencl_runtime.configure(mode="require")
    try:
        runtime = opencl_runtime.get_runtime()
    except OpenCLUnavailableError as err:
        tier_unavailable(str(err))
    yield runtime
    opencl_runtime.configure()


@pytest.fixture
def addon_opencl(addon_module):
    """The OpenCL runtime of the add-on's own copy of the kernels (``bl_ext…``: the copy its operators run, not the
    ``tessera.`` copy `opencl` configures), required; the add-on's preferences are applied again after."""
    runtime_module = addon_module("kernels.common.opencl_runtime")
    errors = addon_module("kernels.common.errors")
    runtime_module.configure(mode="require")
    try:
        runtime = runtime_module.get_runtime()
    except errors.OpenCLUnavailableError as err:
        tier_unavailable(str(err))
    yield runtime
    import bpy

    addon_module("addon.preferences").apply_opencl_settings(bpy.context.preferences.addons[ADDON_MODULE].preferences)


@pytest.fixture(scope="session")
def built_zips(bpy_module, tmp_root):
    """The extension zips: those in $TESSERA_ZIP_DIR when set (`make test-all` builds them once for every Blender),
    else built once for this session (`tools/build_extension.py`, what `make build` runs)."""
    given = os.environ.get("TESSERA_ZIP_DIR")
    if given:
        zips = sorted(Path(given).glob("tessera-*.zip"))
        assert zips, f"TESSERA_ZIP_DIR={given} holds no tessera-*.zip"
        return zips
    out = tmp_root / "dist"
    env = dict(os.environ, BLENDER_USER_RESOURCES=str(tmp_root / "build_user"))
    proc = subprocess.run([sys.executable, str(ROOT / "tools" / "build_extension.py"), "--out", str(out),
                           "--wheels", str(tmp_root / "wheels")], capture_output=True, text=True, env=env,
                          timeout=900)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return sorted(out.glob("tessera-*.zip"))


class Recorder:
    """A stand-in for `bpy.types.UILayout` that records the label of every property row (a heading prefixes the
    rows under it, and a box makes a section of its own, as Blender shows them) and accepts every other call."""

    def __init__(self, rows, heading="", fields=None):
        self.rows, self.heading = rows, heading
        self.fields = [] if fields is None else fields  # (label, property type) of every row, shared by children
        self.boxes = 0

    def prop(self, data, name, text=None, **_):
        label = text if text is not None else data.bl_rna.properties[name].name
        if label:
            self.rows.append(f"{self.heading}{label}")
            self.fields.append((label, data.bl_rna.properties[name].type))

    def _child(self, heading=""):
        return Recorder(self.rows, f"{self.heading}{heading}: " if heading else self.heading, self.fields)

    def column(self, align=False, heading="", **_):
        return self._child(heading)

    def row(self, align=False, heading="", **_):
        return self._child(heading)

    def box(self):
        self.boxes += 1
        return Recorder(self.rows, f"{self.heading}box {self.boxes}: ", self.fields)

    def split(self, **_):
        return self._child()

    def operator(self, *args, **kwargs):
        return SimpleNamespace()

    def __getattr__(self, name):  # label, separator, template_*, menu, popover ...: nothing to record
        return lambda *args, **kwargs: self._child()


@pytest.fixture(params=["gdal", "tiff"])
def elevation_reader(request, monkeypatch):
    """Each elevation reader in turn: GDAL (the bundled rasterio), and the TIFF reader a zip falls back to where
    GDAL does not load (made to believe rasterio is missing)."""
    from tessera.kernels.terrain import gdal_raster

    if request.param == "gdal":
        pytest.importorskip("rasterio")
    else:
        monkeypatch.setattr(gdal_raster, "why_not", lambda: "rasterio is not installed (a test)")
    return request.param

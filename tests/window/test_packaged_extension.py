"""The built zip in the packaged Blender (Debian's 5.2.x on the system Python 3.14, as every Linux distribution builds
it), installed as a user installs it from a terminal: ``blender --command extension install-file -e``, one tool run
through ``blender --command tessera``, then ``blender --command extension remove``; nothing of it is left."""

import json
import re
import shutil
import subprocess

import numpy as np
import pytest
from conftest import ROOT
from window_tier import window_blender  # noqa: F401 -- fixture

pytestmark = pytest.mark.window

#: Runs inside the chroot (tools/packaged_run.sh): each step's output and exit code into /tessera-out.
STEPS = r"""
set -u
out=/tessera-out
ext=/tmp/blender-user/extensions
step() { name=$1; shift; "$@" >"$out/$name.log" 2>&1; echo $? >"$out/$name.rc"; }
step install blender --command extension install-file -r user_default -e "$out/$ZIP"
ls "$ext/.local/lib/"python3*/site-packages >"$out/site_installed.txt" 2>&1
step tessellate blender --command tessera tessellate --level 2 -o "$out/cube.ply" --json "$out/summary.json"
step terrain blender --command tessera terrain "$out/dem.asc" --mode uniform --tile-size 8 --no-culling \
  -o "$out/dem.ply" --json "$out/terrain.json"
step opencl blender --background --python-expr "
import importlib, json, sys
rt = importlib.import_module('bl_ext.user_default.tessera.kernels.common.opencl_runtime').get_runtime()
budget = importlib.import_module('bl_ext.user_default.tessera.kernels.common.budget')
gdal = importlib.import_module('bl_ext.user_default.tessera.kernels.terrain.gdal_raster')
import psutil, pyopencl, rasterio
print('RESULT' + json.dumps({'device': rt is not None and rt.device.name, 'pyopencl': pyopencl.__file__,
                             'psutil': psutil.__file__, 'free': budget.free_bytes(), 'gdal': gdal.why_not(),
                             'rasterio': rasterio.__file__, 'python': '%d.%d' % sys.version_info[:2]}))"
step remove blender --command extension remove user_default.tessera
find "$ext" -mindepth 1 -not -path "*/.cache*" -not -name __pycache__ -not -path "*/__pycache__/*" \
  >"$out/left.txt" 2>&1
"""
BUNDLED = ("psutil", "pyopencl", "pytools", "siphash24", "threadpoolctl", "tifffile", "rasterio", "affine", "click")
#: An ESRI ASCII grid (33 rows of 41 samples, 10 m apart, one void), written as text: read by the zip's GDAL.
ROWS, COLS = 33, 41


def _ascii_grid(path):
    heights = (100.0 + np.add.outer(np.arange(ROWS) * 1.5, np.arange(COLS) * 0.25)).round(2)
    heights[20, 7] = -9999.0
    lines = [f"ncols {COLS}", f"nrows {ROWS}", "xllcorner 500000", "yllcorner 4600000", "cellsize 10",
             "NODATA_value -9999"] + [" ".join(f"{v:g}" for v in row) for row in heights]
    path.write_text("\n".join(lines) + "\n")
    return heights


@pytest.fixture(scope="module")
def packaged_install(window_blender, built_zips, tmp_root):  # noqa: F811 -- fixture
    out = tmp_root / "packaged_install"
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)
    linux = next(z for z in built_zips if z.name.endswith("linux_x64.zip"))
    shutil.copy2(linux, out / linux.name)
    _ascii_grid(out / "dem.asc")
    (out / "steps.sh").write_text(STEPS)
    done = subprocess.run(["bash", str(ROOT / "tools" / "packaged_run.sh"), str(out), "600", "--",
                           "env", f"ZIP={linux.name}", "bash", "/tessera-out/steps.sh"],
                          capture_output=True, text=True, timeout=700)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    return out


def _step(out, name):
    log = (out / f"{name}.log").read_text(errors="replace")
    return int((out / f"{name}.rc").read_text()), log


def test_install_file_enables_it(packaged_install):
    rc, log = _step(packaged_install, "install")
    assert rc == 0 and 'Installed "tessera"' in log, log[-2000:]
    assert "isn't compatible" not in log
    listing = (packaged_install / "site_installed.txt").read_text().split()
    site = {entry.split(".")[0].split("-")[0] for entry in listing}
    for name in BUNDLED:  # the wheels for this Python, from the zip
        assert name in site, f"{name} was not installed from the zip's wheels: {sorted(site)}"


def test_a_tool_runs_from_the_command_line(packaged_install):
    rc, log = _step(packaged_install, "tessellate")
    assert rc == 0, log[-2000:]
    assert "Traceback" not in log
    summary = json.loads((packaged_install / "summary.json").read_text())
    assert summary["ok"] and summary["results"][0]["faces"] == 12 * 6  # the start-up cube, level 2: 6 per triangle
    head = (packaged_install / "cube.ply").read_bytes()[:400].decode("ascii", "replace")
    assert re.search(r"element face 72\b", head), head


def test_an_ascii_grid_becomes_a_terrain_through_the_zips_gdal(packaged_install):
    rc, log = _step(packaged_install, "terrain")
    assert rc == 0 and "Traceback" not in log, log[-2000:]
    summary = json.loads((packaged_install / "terrain.json").read_text())
    # Uniform on whole tiles of 8: every sample a vertex, the void filled (not a pit)
    assert summary["ok"] and summary["results"][0]["vertices"] == ROWS * COLS
    assert summary["results"][0]["faces"] == 2 * (ROWS - 1) * (COLS - 1)


def test_the_bundled_pyopencl_finds_a_device(packaged_install):
    rc, log = _step(packaged_install, "opencl")
    lines = [line for line in log.splitlines() if line.startswith("RESULT")]
    assert rc == 0 and lines, log[-2000:]
    report = json.loads(lines[-1][len("RESULT"):])
    assert report["python"] == "3.14"
    assert "/extensions/.local/" in report["pyopencl"]  # the zip's wheel, not the distribution's package
    assert "/extensions/.local/" in report["psutil"] and report["free"] > 2**20
    assert "/extensions/.local/" in report["rasterio"] and report["gdal"] == ""  # the zip's GDAL loads
    assert report["device"], "the bundled pyopencl found no OpenCL device (PoCL)"


def test_remove_leaves_nothing(packaged_install):
    rc, log = _step(packaged_install, "remove")
    assert rc == 0 and 'Removed "tessera"' in log, log[-2000:]
    left = [line for line in (packaged_install / "left.txt").read_text().splitlines()
            if any(part in line for part in ("tessera",) + BUNDLED)]
    assert left == [], left

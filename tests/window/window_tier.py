"""Fixtures of the window tier (test modules import them): scenarios in a real Blender window, Debian's packaged
Blender under Xvfb with Mesa, events injected by Blender's --enable-event-simulate (`tools/window_run.sh`). Needs
root (debootstrap, chroot and a private mount namespace) and Debian's packages; elsewhere the tier is unavailable
(skipped, or failed under CI)."""

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest
from conftest import ROOT, tier_unavailable

#: The GPU backends the tier runs each scenario on: Mesa llvmpipe (OpenGL) and lavapipe (Vulkan).
BACKENDS = ("opengl", "vulkan")
_RUNS = {}


def _why_unavailable():
    if os.geteuid() != 0:
        return "the window tier needs root (a chroot with Debian's Blender, mounts in a private namespace)"
    if shutil.which("unshare") is None or shutil.which("chroot") is None:
        return "the window tier needs unshare and chroot (util-linux, coreutils)"
    return None


@pytest.fixture(scope="session")
def window_blender():
    """The chroot with the packaged Blender (made once per machine by tools/window_setup.sh)."""
    why = _why_unavailable()
    if why:
        tier_unavailable(why)
    done = subprocess.run(["bash", str(ROOT / "tools" / "window_setup.sh")], capture_output=True, text=True)
    if done.returncode != 0:
        pytest.fail(f"the window tier could not set up its Blender: {done.stderr.strip()[-2000:]}", pytrace=False)
    return Path(done.stdout.strip().splitlines()[-1])


@pytest.fixture(scope="session")
def run_scenario(window_blender, tmp_root):
    """Run a scenario once per session and backend: ``run_scenario(name, backend)`` -> (results dict, log text,
    its output folder with the screenshots). A scenario that does not finish fails the test with its error."""

    def run(name, backend):
        key = (name, backend)
        if key not in _RUNS:
            out = Path(os.environ.get("TESSERA_WINDOW_OUT", tmp_root / "window")) / f"{name}-{backend}"
            shutil.rmtree(out, ignore_errors=True)
            done = subprocess.run(["bash", str(ROOT / "tools" / "window_run.sh"), str(out), name, backend, "300"],
                                  capture_output=True, text=True)
            log = (out / "blender.log").read_text(errors="replace") if (out / "blender.log").exists() else ""
            results_file = out / "results.json"
            if not results_file.exists():
                pytest.fail(f"the window scenario {name} ({backend}) did not finish (exit {done.returncode}):\n"
                            f"{done.stderr[-2000:]}\n{log[-4000:]}", pytrace=False)
            _RUNS[key] = (json.loads(results_file.read_text()), log, out)
        results, log, out = _RUNS[key]
        if not results.get("finished"):
            pytest.fail(f"the window scenario {name} ({backend}) stopped:\n{results.get('error')}", pytrace=False)
        return results, log, out

    return run


def scenario_fixture(scenario, name=None):
    """A fixture (named ``name``, default the scenario's) that runs ``scenario`` once per backend of `BACKENDS`:
    (results, log, the output folder). Assign it in a test module: ``brush = scenario_fixture("brush")``."""

    @pytest.fixture(params=BACKENDS, name=name or scenario)
    def fixture(request, run_scenario):
        return run_scenario(scenario, request.param)

    return fixture


def assert_no_traceback(log):
    """The scenario's Blender printed no traceback."""
    assert log.count("Traceback") == 0, f"the session printed a traceback:\n{log[-3000:]}"

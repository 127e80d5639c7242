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


#: A picture of the manual against the same shot taken now: at most this share of the pixels of the view's middle
#: (half its width, 60 % of its height: what the shot is about, not the header or toolbars a newer Blender may
#: redraw) differ by > 16/255 in a channel. The same run gives 0; the quick start's flat monkey shown for its smooth
#: one, about 9 %.
PICTURE_BAR = 0.03


def picture_drift(shown, made):
    """The share of the middle of picture file ``shown`` (in docs/shots/, scaled by tools/manual_shots.sh) that
    differs from the screenshot file ``made``, scaled the same way: compare with `PICTURE_BAR`."""
    import numpy as np
    import OpenImageIO as oiio

    shown_buf, made_buf = oiio.ImageBuf(str(shown)), oiio.ImageBuf(str(made))
    spec = shown_buf.spec()
    made_buf = oiio.ImageBufAlgo.resize(made_buf, roi=oiio.ROI(0, spec.width, 0, spec.height, 0, 1, 0, 3))
    a = shown_buf.get_pixels(oiio.UINT8)[..., :3].astype(np.int16)
    b = made_buf.get_pixels(oiio.UINT8)[..., :3].astype(np.int16)
    h, w = a.shape[:2]
    middle = (slice(h // 5, h - h // 5), slice(w // 4, w - w // 4))
    return float((np.abs(a[middle] - b[middle]) > 16).any(axis=2).mean())


def assert_picture_current(out, name):
    """docs/shots/NAME.png is what the scenario whose output folder is ``out`` shot as ``shot_NAME.png`` now."""
    share = picture_drift(ROOT / "docs" / "shots" / f"{name}.png", Path(out) / f"shot_{name}.png")
    assert share <= PICTURE_BAR, (f"{share:.1%} of docs/shots/{name}.png differs from what its steps give now: run "
                                  f"tools/manual_shots.sh ({out})")


def scenario_constant(scenario, name):
    """The literal value of module constant ``name`` of scenario ``scenario`` (tests/window/scenarios), read without
    Blender."""
    import ast

    tree = ast.parse((ROOT / "tests" / "window" / "scenarios" / f"{scenario}.py").read_text())
    node = next(n for n in tree.body if isinstance(n, ast.Assign) and getattr(n.targets[0], "id", "") == name)
    return ast.literal_eval(node.value)


def assert_menu_labels(results):
    """Each menu path a scenario ran (``results["labels"]``: words -> the operator's label) ends in that label:
    *Object › Shade Smooth* runs the operator Blender calls *Shade Smooth*, and an item of the Add menu the one
    called *Add* and the item (*Add › Mesh › Monkey*: *Add Monkey*)."""
    labels = results["labels"]
    assert labels, "the scenario ran no menu step"
    wrong = {words: label for words, label in labels.items()
             if label not in (words.split(" › ")[-1], "Add " + words.split(" › ")[-1])}
    assert not wrong, f"menu paths whose last item is not the operator's label: {wrong}"


def assert_steps_in_order(text, steps, where):
    """``text`` (a numbered list of a page) names each step's words as ``*words*``, in the order of ``steps`` ((words,
    operator, arguments), ...), and stays one numbered list, pictures inside, in the manual's HTML (as
    tools/manual.py makes it)."""
    import markdown

    at = -1
    for words, _, _ in steps:
        found = text.find(f"*{words}*", at + 1)
        assert found > at, f"{where} does not name *{words}* (in this order)"
        at = found
    html = markdown.markdown(text, extensions=["tables", "fenced_code", "toc"])
    assert html.count("<ol>") == 1 and html.index("<ol>") < html.index("<img") < html.index("</ol>"), html

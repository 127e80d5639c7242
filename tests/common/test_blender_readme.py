"""Every code block of the README runs, exactly as printed, top to bottom as a new user would follow it, in a
folder of its own holding the built Linux zip (tier: blender).

- ``python`` blocks whose first line names a file (``# monkey_pn.py``) are written to that file; other ``python``
  blocks run in the ``bpy`` module;
- ``sh`` blocks run in bash with ``blender`` on PATH: Debian's packaged Blender (Python 3.14) where it runs here
  (root: the window tier's chroot), else `blender_cli.py`, the ``bpy`` module standing in for the executable
  (Blender's own extension command, user preferences and enabled add-ons loaded at startup as Blender loads them).
  A block that starts ``# on the farm`` runs with a user folder of its own, where Tessera was never installed;
- the ``make`` block (the two commands) is checked, not run (it is what CI runs): every target exists and ``make -n``
  accepts it, and ``.ci/run`` runs ``make test``.

Then what the snippets say they make is there: the OBJ with the tessellated monkey, the tubes, the farm's frame.
"""

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from blender_helpers import cli_blender_on_path

pytestmark = pytest.mark.blender

ROOT = Path(__file__).resolve().parents[2]
FENCE = re.compile(r"^```(\w*)\n(.*?)^```", re.MULTILINE | re.DOTALL)
FILE_LINE = re.compile(r"#\s*([\w.-]+\.py)\s*$")


def readme_blocks():
    """(language, code) of every fenced block of the README, in order."""
    return [(m.group(1), m.group(2)) for m in FENCE.finditer((ROOT / "README.md").read_text(encoding="utf-8"))]


def _make_block(code):
    targets = set(re.findall(r"(?m)^([\w-]+):", (ROOT / "Makefile").read_text(encoding="utf-8")))
    lines = [line.split("#")[0].split() for line in code.splitlines() if line.strip()]
    assert lines and all(words[0] == "make" and len(words) == 2 for words in lines), code
    for _, target in lines:
        assert target in targets, f"make {target}: no such target"
        proc = subprocess.run(["make", "-n", target], cwd=ROOT, capture_output=True, text=True, timeout=60)
        assert proc.returncode == 0, proc.stderr
    assert "make test" in (ROOT / ".ci" / "run").read_text(encoding="utf-8")


def test_every_readme_block_runs_as_printed(built_zips, tmp_path):
    blocks = readme_blocks()
    assert len(blocks) >= 8
    linux = next(z for z in built_zips if z.name.endswith("linux_x64.zip"))
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert linux.name in readme  # the snippets name the zip the build makes
    home = tmp_path / "home"
    home.mkdir()
    shutil.copy2(linux, home / linux.name)
    env, _ = cli_blender_on_path(tmp_path, [tmp_path])
    env = dict(env, BLENDER_USER_RESOURCES=str(tmp_path / "user"))
    farm_env = dict(env, BLENDER_USER_RESOURCES=str(tmp_path / "farm_user"))
    printed = []
    for language, code in blocks:
        first = code.splitlines()[0] if code.strip() else ""
        if language == "python" and FILE_LINE.match(first):
            (home / FILE_LINE.match(first).group(1)).write_text(code, encoding="utf-8")
            continue
        if language == "sh" and code.lstrip().startswith("make "):
            _make_block(code)
            continue
        if language == "python":
            cmd, run_env = [sys.executable, "-c", code], env
        elif language == "sh":
            cmd = ["bash", "-e", "-c", code]
            run_env = farm_env if first.startswith("# on the farm") else env
        else:
            pytest.fail(f"a README block in {language or 'no language'} that this test cannot run:\n{code}")
        proc = subprocess.run(cmd, cwd=home, env=run_env, capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, f"{code}\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
        printed.append(proc.stdout)

    # blender -b --python monkey_pn.py: Suzanne's 968 triangles at uniform level 4, 24 each
    faces = sum(1 for line in (home / "monkey_pn.obj").read_text().splitlines() if line.startswith("f "))
    assert faces == 968 * 24
    # blender -c tessera: the monkey again, as glTF, and the summary line
    assert (home / "monkey_smooth.glb").stat().st_size > 968 * 24 * 4 * 12
    summaries = [json.loads(line) for out in printed for line in out.splitlines() if line.startswith('{"verb": ')]
    assert summaries and summaries[0]["ok"] and summaries[0]["results"][0]["faces"] > 968 * 24 * 2  # finer again
    # the bpy module's script: round-capped tubes around the circle
    counts = [int(m.group(1)) for out in printed for m in re.finditer(r"^(\d+) faces$", out, re.MULTILINE)]
    assert counts and counts[-1] > 100
    # the farm: the shot saved with Tessera, rendered where Tessera was never installed, showing the monkey
    assert (home / "shot.blend").exists()
    assert not (tmp_path / "farm_user" / "extensions" / "user_default" / "tessera").exists()
    assert (tmp_path / "user" / "extensions" / "user_default" / "tessera").exists()
    import OpenImageIO as oiio

    frame = oiio.ImageBuf(str(home / "frame_0001.png"))
    pixels = frame.get_pixels(oiio.FLOAT)
    assert pixels.shape[:2] == (360, 640)
    lum = pixels[..., :3].mean(axis=-1)
    assert (abs(lum - float(lum.mean())) > 0.05).mean() > 0.02  # a shaded object, not an empty frame

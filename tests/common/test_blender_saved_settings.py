"""A .blend saved by an earlier Tessera opens with every setting intact (tier: blender).

``tests/data/saved_settings.blend`` was written by Blender 4.2 with the add-on as it was at commit 3c12feb
(``tools/saved_settings.py tests/data --tree <that commit's tree>``): every stored setting on an object, the scene's
brush and an image at a value other than its default, and ``saved_settings.json`` the values it read back. Renaming a
stored identifier, or changing an enum's identifiers, would drop the artist's value without a word; here it fails
the test. Run in a process of its own: opening a file replaces the whole of ``bpy.data``."""

import json
import subprocess
import sys

import pytest
from conftest import REPO_DIR, ROOT

pytestmark = pytest.mark.blender

SCRIPT = r"""
import json, sys
sys.path[:0] = [REPO, TOOLS]
import bpy
from source_tree import enable_extension
enable_extension(REPO, "saved")
from saved_settings import read
want, got = read(FILE)
print("RESULT" + json.dumps({"want": want, "got": got}), flush=True)
"""


def test_a_file_saved_before_opens_with_every_setting(tmp_path):
    head = (f"REPO = {str(REPO_DIR)!r}\nTOOLS = {str(ROOT / 'tools')!r}\n"
            f"FILE = {str(ROOT / 'tests' / 'data' / 'saved_settings.blend')!r}\n")
    proc = subprocess.run([sys.executable, "-c", head + SCRIPT], capture_output=True, text=True, timeout=600,
                          cwd=str(tmp_path))
    lines = [line for line in proc.stdout.splitlines() if line.startswith("RESULT")]
    assert proc.returncode == 0 and lines, proc.stdout[-3000:] + proc.stderr[-3000:]
    result = json.loads(lines[-1][len("RESULT"):])
    want, got = result["want"], result["got"]
    groups = {".".join(key.split(".")[:3]) for key in want}
    assert len(want) >= 100 and len(groups) >= 9  # every capability's group, the brush and the image
    lost = {key: (value, got[key]) for key, value in want.items() if got[key] != value}
    assert not lost, f"settings changed on opening a file saved before: {lost}"

"""The figures the manual's demo captions give are what the demo's scenes make (tier: blender): the scenes built as
``make demo`` builds them (`samples/demo.py`'s ``caption_figures``, no rendering), in a Blender process of their own,
then each caption read from its page (the captions give ``make demo``'s figures: the newest supported Blender's where
Blender's own nodes make them). A changed default, level rule or scene changes the figure, and this fails until
the caption says the new one."""

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.blender

ROOT = Path(__file__).resolve().parents[2]
RUN = """
import json, sys
sys.path.insert(0, sys.argv[1])
import demo
demo.enable_addon()
print("FIGURES " + json.dumps(demo.caption_figures()))
"""


def number(text):
    return int(text.replace(",", ""))


def caption(page, pattern):
    """The groups of ``pattern`` in docs/``page`` (the caption must be there: a reworded caption fails here)."""
    found = re.search(pattern, (ROOT / "docs" / page).read_text(encoding="utf-8"))
    assert found, f"docs/{page} has no caption matching {pattern!r}"
    return found.groups()


@pytest.fixture(scope="module")
def figures(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("demo_figures")
    env = dict(os.environ, TESSERA_DEMO_OUT=str(tmp), BLENDER_USER_RESOURCES=str(tmp / "user"))
    proc = subprocess.run([sys.executable, "-c", RUN, str(ROOT / "samples")], capture_output=True, text=True,
                          env=env, timeout=600)
    line = next((ln for ln in proc.stdout.splitlines() if ln.startswith("FIGURES ")), None)
    assert proc.returncode == 0 and line, proc.stdout[-3000:] + proc.stderr[-3000:]
    return json.loads(line.removeprefix("FIGURES "))


def test_tessellation_captions(figures):
    (each,) = caption("tessellation.md", r"level 4: ([\d,]+) triangles each")
    assert set(figures["methods_triangles"].values()) == {number(each)}, figures["methods_triangles"]
    near_to_far = caption("tessellation.md", r"([\d,]+) / ([\d,]+) / ([\d,]+) / ([\d,]+) triangles\s+from near to far")
    assert [number(n) for n in near_to_far] == figures["adaptive_triangles"]


def test_terrain_caption(figures):
    thousands, share = caption("terrain.md", r"(\d+)k triangles, ([\d.]+)% of the full grid")
    tris, full = figures["terrain_triangles"], figures["terrain_full_grid"]
    assert int(thousands) == round(tris / 1000) and float(share) == round(100 * tris / full, 1), (tris, full)


def test_loop_caption(figures):
    coarse, level2 = caption("subdivision.md", r"Suzanne \(([\d,]+) triangles after its quads are split\), "
                                               r"Loop level 2 \(([\d,]+) triangles\)")
    assert number(level2) == figures["loop_triangles"]["Suzanne"] == 16 * number(coarse)


def docs_blender():
    """(major, minor) of the Blender ``make demo`` runs, the newest supported (requirements/blender-X.Y.txt)."""
    return max(tuple(int(n) for n in p.stem.removeprefix("blender-").split("."))
               for p in (ROOT / "requirements").glob("blender-*.txt"))


def test_node_groups_caption(figures):
    pn, terrain = caption("node_groups.md", r"(?s)Subdivisions 2, ([\d,]+)\s+faces\).*?([\d,]+) faces, a quarter "
                                            r"of the full grid")
    pn_faces, _, _, terrain_faces = figures["node_groups_faces"]
    assert number(terrain) == terrain_faces
    import bpy

    if bpy.app.version[:2] == docs_blender():
        assert number(pn) == pn_faces
    else:  # Blender's own Subdivide Mesh node, which the group runs, differs a little by version (4.5: 12 more quads)
        assert abs(number(pn) - pn_faces) <= 0.005 * pn_faces, (number(pn), pn_faces)
    assert terrain_faces == 128 ** 2 // 4  # the 129² image: 128² quads in the full grid

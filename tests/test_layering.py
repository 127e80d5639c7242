"""The layering rule: `kernels` imports no Blender module, enforced by importing it with them blocked."""

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

BLOCKER = r"""
import importlib, importlib.abc, pkgutil, sys
BLOCKED = {"bpy", "gpu", "mathutils", "bmesh", "gpu_extras", "bpy_extras", "bl_math"}

class Block(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in BLOCKED:
            raise ImportError(f"kernels must not import {name}")
        return None

sys.meta_path.insert(0, Block())
import tessera.kernels as k
names = [m.name for m in pkgutil.walk_packages(k.__path__, "tessera.kernels.")]
for name in names:
    importlib.import_module(name)
print(len(names))
"""


def test_kernels_import_without_blender(tmp_root):
    env = dict(os.environ, PYTHONPATH=str(tmp_root / "repo"))
    proc = subprocess.run([sys.executable, "-c", BLOCKER], capture_output=True, text=True, env=env, timeout=120)
    assert proc.returncode == 0, proc.stderr
    modules = {p.stem for p in (ROOT / "kernels").glob("*.py") if p.stem != "__init__"}
    assert int(proc.stdout.strip()) == len(modules)


def test_blocker_catches_a_violation(tmp_root):
    env = dict(os.environ, PYTHONPATH=str(tmp_root / "repo"))
    proc = subprocess.run([sys.executable, "-c", BLOCKER.replace("import tessera.kernels as k", "import bpy")],
                          capture_output=True, text=True, env=env, timeout=120)
    assert proc.returncode != 0 and "must not import bpy" in proc.stderr

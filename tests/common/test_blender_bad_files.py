"""Corrupt image files through the operators that read them, one fresh Blender process per file (a reader
crash must show as a failed case, not take the test run down): each ends in a result with finite data or a
refusal that names the file and says why, with nothing left behind (tier: blender)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.blender
HERE = Path(__file__).resolve().parent


def _valid_file(path):
    import OpenImageIO as oiio

    y, x = np.mgrid[0:48, 0:40]
    heights = (0.5 + 0.4 * np.sin(x / 5.0) * np.cos(y / 7.0)).astype(np.float32)
    fmt = {".png": "uint16", ".exr": "float", ".tif": "uint16"}[path.suffix]
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), oiio.ImageSpec(40, 48, 1, fmt)) and out.write_image(heights), oiio.geterror()
    out.close()
    return path.read_bytes()


def _corrupt(data, how, seed):
    rng = np.random.default_rng(seed)
    if how == "truncated":
        return data[: len(data) * 2 // 3]
    if how == "header":
        return data[:8] + bytes(rng.integers(0, 256, 64, dtype=np.uint8)) + data[72:]
    b = np.frombuffer(data, np.uint8).copy()  # "flipped": bytes changed all through the file
    idx = rng.choice(np.arange(16, len(b)), size=max(1, len(b) // 50), replace=False)
    b[idx] ^= rng.integers(1, 256, idx.size, dtype=np.uint8)
    return b.tobytes()


@pytest.mark.parametrize("how", ["truncated", "header", "flipped"])
@pytest.mark.parametrize("suffix", [".png", ".exr", ".tif"])
def test_a_corrupt_file_never_crashes_nor_half_changes_the_scene(tmp_root, tmp_path, bpy_module, suffix, how):
    path = tmp_path / f"{how}{suffix}"
    path.write_bytes(_corrupt(_valid_file(path), how, seed=len(how) * 7 + len(suffix)))
    env = dict(os.environ, BLENDER_USER_RESOURCES=str(tmp_path / "user"))
    proc = subprocess.run([sys.executable, str(HERE / "bad_file_case.py"), str(tmp_root / "repo"), str(path)],
                          capture_output=True, text=True, env=env, timeout=300)
    results = [json.loads(line[7:]) for line in proc.stdout.splitlines() if line.startswith("RESULT ")]
    assert proc.returncode == 0 and len(results) == 2, proc.stdout[-2000:] + proc.stderr[-2000:]
    for r in results:
        assert r["finite"], r
        if r["outcome"] == ["CANCELLED"]:
            assert not r["changed"], r
            assert path.name in r["message"] and "Traceback" not in r["message"], r
            reason = r["message"].split(path.name, 1)[1].strip(" :'\"\n")
            assert len(reason) > 5, r  # says why, not just which file
        else:
            assert r["outcome"] == ["FINISHED"] and r["changed"], r

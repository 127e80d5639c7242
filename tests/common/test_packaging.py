"""Build the extension zips with Blender's builder, then install, enable, run and uninstall one in a
fresh Blender process, the way a user installs it from disk (tier: blender)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.blender
ROOT = Path(__file__).resolve().parents[2]

INSTALL_AND_RUN = r"""
import json, sys, bpy, addon_utils
zip_path = sys.argv[1]
prefs = bpy.context.preferences
repo_index = next(i for i, r in enumerate(prefs.extensions.repos) if r.module == "user_default")
installed = bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default", enable_on_install=True)
assert installed == {"FINISHED"}
module = "bl_ext.user_default.tessera"
enabled = module in prefs.addons
bpy.ops.mesh.primitive_cube_add()
result = bpy.ops.tessera.tessellate(level=2)
faces = len(bpy.context.active_object.data.polygons)
import glob, os
local = bpy.utils.user_resource("EXTENSIONS", path=".local")
def bundled():
    names = {os.path.basename(p).split(".")[0]
             for p in glob.glob(os.path.join(local, "lib", "python*", "site-packages", "*"))}
    return sorted(names & {"pyopencl", "pytools", "siphash24", "threadpoolctl"})
wheels_installed = bundled()
bpy.ops.extensions.package_uninstall(repo_index=repo_index, pkg_id="tessera")
print("RESULT" + json.dumps({"enabled": enabled, "result": sorted(result), "faces": faces,
      "wheels": wheels_installed, "wheels_after": bundled(), "after": module in prefs.addons,
      "op_after": hasattr(bpy.types, "TESSERA_OT_tessellate")}))
"""


@pytest.fixture(scope="module")
def built_zips(bpy_module, tmp_root):
    out = tmp_root / "dist"
    env = dict(os.environ, BLENDER_USER_RESOURCES=str(tmp_root / "build_user"))
    proc = subprocess.run([sys.executable, str(ROOT / "tools" / "build_extension.py"), "--out", str(out),
                           "--wheels", str(tmp_root / "wheels")], capture_output=True, text=True, env=env,
                          timeout=900)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return sorted(out.glob("tessera-*.zip"))


def test_one_zip_per_platform_without_dev_files(built_zips):
    import zipfile

    assert {z.name.split("-")[-1] for z in built_zips} == {"linux_x64.zip", "windows_x64.zip", "macos_arm64.zip",
                                                          "macos_x64.zip"}
    for z in built_zips:
        names = zipfile.ZipFile(z).namelist()
        assert "blender_manifest.toml" in names and "kernels/tessellation/gather_weighted.cl" in names
        assert not any(n.startswith(("tests/", "samples/", "bench/", "docs/", ".ci/", "tools/")) for n in names)
        assert any(n.startswith("wheels/pyopencl-") for n in names)
        assert not any("numpy" in n for n in names)


def test_install_enable_run_uninstall(built_zips, tmp_root):
    linux = next(z for z in built_zips if z.name.endswith("linux_x64.zip"))
    user = tmp_root / "install_user"
    env = dict(os.environ, BLENDER_USER_RESOURCES=str(user))
    proc = subprocess.run([sys.executable, "-c", INSTALL_AND_RUN, str(linux)], capture_output=True, text=True,
                          env=env, timeout=600)
    lines = [line for line in proc.stdout.splitlines() if line.startswith("RESULT")]
    assert proc.returncode == 0 and lines, proc.stdout[-3000:] + proc.stderr[-3000:]
    report = json.loads(lines[-1][len("RESULT"):])
    assert report["enabled"] and report["result"] == ["FINISHED"]
    assert report["faces"] == 12 * 6  # cube: 12 triangles, level 2 -> 6 each
    assert report["wheels"] == ["pyopencl", "pytools", "siphash24", "threadpoolctl"]  # bundled wheels were installed
    assert report["wheels_after"] == []  # and removed with the extension
    assert not report["after"] and not report["op_after"]

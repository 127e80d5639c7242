"""Build the Tessera extension zips with Blender's own builder, one per platform, wheels bundled.

Steps: validate the source manifest (tags checked against Blender's list); download the wheels of pyopencl and its
pure-Python needs, of rasterio (GDAL and PROJ, for elevation files) and its pure-Python needs, of tifffile (GeoTIFF tags
where GDAL does not load) and of psutil (free memory), for each platform and for each Python the supported Blenders
use (3.11 for 4.2-5.0, 3.13 for 5.1 and 5.2, 3.14 for the distributions' builds), at the versions the tests ran with
(this venv's; the 3.11 Blenders' requirements file for 3.11, where a package pins another version); stage a copy of
the tree whose manifest lists them, with the node-group asset library written into it by this venv's Blender and the
manual as HTML (`manual.py`); build with ``blender_ext.py build --split-platforms``; validate each zip.
Blender installs the wheels that match its own Python. numpy is not bundled: Blender ships it.

Usage: python tools/build_extension.py [--out dist] [--wheels wheels]
"""

import argparse
import shutil
import subprocess
import sys
import tempfile
import tomllib
from importlib import metadata
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from manual import build_manual  # noqa: E402 -- tools/ is not a package

ROOT = Path(__file__).resolve().parents[1]
# Blender platform -> pip platform tags for the binary wheels.
PLATFORMS = {
    "linux-x64": ["manylinux_2_28_x86_64", "manylinux_2_27_x86_64", "manylinux_2_17_x86_64", "manylinux2014_x86_64"],
    "windows-x64": ["win_amd64"],
    "macos-arm64": ["macosx_15_0_arm64"],
    "macos-x64": ["macosx_15_0_x86_64"],
}
BINARY = ("pyopencl", "siphash24", "psutil", "rasterio")
PURE = ("pytools", "platformdirs", "typing_extensions", "threadpoolctl", "tifffile", "affine", "attrs", "certifi",
        "click")
#: The requirements file of each Python's Blenders, for a version other than this venv's (rasterio 1.5 needs 3.12).
REQUIREMENTS = {"3.11": ROOT / "requirements" / "blender-5.0.txt"}
#: The Pythons of the supported Blenders: 4.2, 4.5 and 5.0 use 3.11; 5.1 and 5.2 use 3.13; the distributions' builds
#: of them (Debian, Ubuntu, Fedora, Arch, NixOS) run the system's Python, 3.14 today.
PYTHONS = ("3.11", "3.13", "3.14")
IGNORE = shutil.ignore_patterns(".git", ".venv*", "out", "dist", "wheels", "__pycache__", ".pytest_cache",
                                ".ruff_cache", ".hypothesis", "*.zip")


def blender_ext(*args):
    """Run Blender's extension CLI (bl_pkg) from the bpy module, so tags are validated too."""
    code = ("import sys, bpy; from bl_pkg import bl_extension_cli as c; "
            "sys.exit(c.cli_extension_handler(sys.argv[1:]))")
    subprocess.run([sys.executable, "-c", code, *args], check=True)


def pip_download(spec, dest, platforms=None, python=None):
    cmd = [sys.executable, "-m", "pip", "download", "-q", "--no-deps", "--only-binary=:all:", "-d", str(dest)]
    if platforms:
        cmd += ["--python-version", python, "--implementation", "cp"]
        for tag in platforms:
            cmd += ["--platform", tag]
    subprocess.run(cmd + [spec], check=True)


def pinned(name, python):
    """The version of ``name`` for ``python``: its pin in that Python's requirements file, else this venv's."""
    path = REQUIREMENTS.get(python)
    if path is not None:
        for line in path.read_text(encoding="utf-8").splitlines():
            spec = line.split("#")[0].strip()
            if spec.lower().startswith(name.lower() + "=="):
                return spec.split("==", 1)[1]
    return metadata.version(name)


def fetch_wheels(dest):
    """Download every needed wheel into ``dest``; returns the file names, sorted."""
    dest.mkdir(parents=True, exist_ok=True)
    for name in PURE:
        pip_download(f"{name}=={metadata.version(name)}", dest)
    for platform, tags in PLATFORMS.items():
        for python in PYTHONS:
            for name in BINARY:
                try:
                    pip_download(f"{name}=={pinned(name, python)}", dest, tags, python)
                except subprocess.CalledProcessError as err:
                    raise SystemExit(f"No {name} wheel for {platform} (Python {python}); the zip cannot be "
                                     "built") from err
    return sorted(p.name for p in dest.glob("*.whl"))


def stage(wheel_dir, wheels, staging):
    shutil.copytree(ROOT, staging, ignore=IGNORE, symlinks=False)
    (staging / "wheels").mkdir()
    for name in wheels:
        shutil.copy2(wheel_dir / name, staging / "wheels" / name)
    manifest = (staging / "blender_manifest.toml").read_text(encoding="utf-8")
    listing = ",\n".join(f'  "./wheels/{name}"' for name in wheels)
    platforms = ", ".join(f'"{p}"' for p in PLATFORMS)
    head, sep, tail = manifest.partition("\n[permissions]")
    manifest = f"{head}\nplatforms = [{platforms}]\nwheels = [\n{listing},\n]\n{sep}{tail}"
    (staging / "blender_manifest.toml").write_text(manifest, encoding="utf-8")
    tomllib.loads(manifest)  # fail here, not in Blender, if the edit broke the TOML
    write_node_library(staging)
    build_manual(staging / "manual")  # the manual, offline: the sidebar's Manual button opens it


#: Writes the node-group library into the staged package (run by this venv's Blender, the bpy module).
_LIBRARY = """
import importlib, sys
from pathlib import Path
staging = Path(sys.argv[1])
sys.path.insert(0, str(staging.parent))
import bpy
library = importlib.import_module(staging.name + ".addon.node_library")
print(library.write_library(staging / "node_library"))
"""


def write_node_library(staging):
    """The .blend of every node group and its catalogs in ``staging/node_library`` (the add-on registers it as the
    "Tessera" asset library when the installing Blender is the one that built it)."""
    subprocess.run([sys.executable, "-c", _LIBRARY, str(staging)], check=True)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "dist")
    parser.add_argument("--wheels", type=Path, default=ROOT / "wheels")
    args = parser.parse_args(argv)
    blender_ext("validate", str(ROOT))
    wheels = fetch_wheels(args.wheels)
    args.out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="tessera-build-") as tmp:
        staging = Path(tmp) / "tessera"
        stage(args.wheels, wheels, staging)
        blender_ext("build", "--source-dir", str(staging), "--output-dir", str(args.out), "--split-platforms")
    version = tomllib.loads((ROOT / "blender_manifest.toml").read_text(encoding="utf-8"))["version"]
    zips = sorted(args.out.glob(f"tessera-{version}-*.zip"))
    for z in zips:
        blender_ext("validate", str(z))
    print("\n".join(str(z) for z in zips))
    return zips


if __name__ == "__main__":
    main()

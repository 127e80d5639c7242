"""Writes that fail where users' disks do (tier: blender, as separate processes; needs root for the mounts): on a
4 MiB file system that fills up, every output format ends in exit 1 and one "no space left" sentence, with nothing
under the final name and no partial file; on a read-only mount the run is refused before any work. Each mount lives
in the test's own mount namespace (``unshare -m``), so nothing stays mounted."""

import os
import shutil
import subprocess
import sys

import pytest
from blender_helpers import installed_blender
from conftest import tier_unavailable

pytestmark = pytest.mark.blender

#: Every format the command line writes (the .gltf with its .bin beside it).
FORMATS = (".obj", ".ply", ".stl", ".glb", ".gltf", ".blend", ".usdc", ".usda", ".abc", ".fbx")
@pytest.fixture(scope="module")
def blender(built_zips, tmp_path_factory):
    if os.geteuid() != 0 or shutil.which("unshare") is None:
        tier_unavailable("the full-disk and read-only tests mount file systems: they need root and unshare")
    return installed_blender(built_zips, tmp_path_factory.mktemp("write_failures_home"),
                             [tmp_path_factory.getbasetemp()])


@pytest.fixture(scope="module")
def sphere(tmp_path_factory):
    """A .blend with one UV sphere (512 faces): tessellated at level 3, every format needs more than `FREE`."""
    path = tmp_path_factory.mktemp("write_failures_scene") / "sphere.blend"
    code = ("import bpy\nbpy.ops.wm.read_homefile(use_empty=True)\nbpy.ops.mesh.primitive_uv_sphere_add()\n"
            f"bpy.ops.wm.save_as_mainfile(filepath={str(path)!r})\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    return path


def _in_namespace(blender, mounts, folder, listing, *args):
    """``blender ARGS`` after the shell lines ``mounts``, in a mount namespace of its own; ``folder``'s contents, as
    the task left them, are listed into the file ``listing`` (outside the mounts). CompletedProcess."""
    script = ("set -e\n" + mounts + "\nset +e\nblender \"$@\"\nrc=$?\n"
              f"ls -A {folder} > {listing}\nexit $rc\n")
    return subprocess.run(["unshare", "-m", "--propagation", "private", "bash", "-c", script, "_", *map(str, args)],
                          env=blender.env, capture_output=True, text=True, timeout=600, cwd=listing.parent)


def _full_disk(blender, sphere, folder, ext, free):
    """Tessellate the sphere onto a 4 MiB file system with ``free`` bytes left: (CompletedProcess, output path,
    what the folder held after)."""
    disk = folder / "disk"
    disk.mkdir()
    listing = folder / "listing.txt"
    mounts = (f"mount -t tmpfs -o size=4m tmpfs {disk}\n"
              f"head -c $((4 * 1024 * 1024 - {free})) /dev/zero > {disk}/filler")
    out = disk / f"sphere{ext}"
    done = _in_namespace(blender, mounts, disk, listing, "-c", "tessera", "tessellate", sphere, "--level", "3",
                         "-o", out)
    return done, out, listing.read_text().split()


@pytest.mark.parametrize("ext", FORMATS)
def test_a_full_disk_fails_with_one_sentence_and_leaves_nothing(blender, sphere, tmp_path, ext):
    whole = tmp_path / f"whole{ext}"
    done = blender("-c", "tessera", "tessellate", sphere, "--level", "3", "-o", whole)
    if done.returncode == 2 and "this Blender was built without the" in done.stderr:  # Debian's has no USD
        assert "Traceback" not in done.stderr and not whole.exists()
        return
    assert done.returncode == 0, done.stderr[-3000:]
    size = sum(p.stat().st_size for p in tmp_path.iterdir() if p.is_file())  # with a .gltf's .bin, an .obj's .mtl
    assert size < 3 * 1024 * 1024
    done, out, left = _full_disk(blender, sphere, tmp_path, ext, size - 32 * 1024)
    said = done.stdout + done.stderr
    assert done.returncode == 1, said[-3000:]
    assert f"{out}: not written: no space left on the device" in said, said[-3000:]
    assert "Traceback" not in said, said[-3000:]
    assert "wrote " not in said
    assert left == ["filler"]  # nothing under the final name, no partial file
    if ext not in (".stl", ".abc"):  # the exporter ran out of space (its file's least size fits): caught after it
        assert "it needs at least" not in said


@pytest.mark.parametrize("ext", [".stl", ".abc", ".obj"])
def test_an_output_that_cannot_fit_is_refused_before_the_exporter(blender, sphere, tmp_path, ext):
    """Refused from the meshes' least size in the format (Alembic's exporter would abort Blender on a full disk)."""
    done, out, left = _full_disk(blender, sphere, tmp_path, ext, 64 * 1024)
    said = done.stdout + done.stderr
    if done.returncode == 2 and "this Blender was built without the" in said:  # Debian's has no Alembic
        assert "Traceback" not in said and left == ["filler"]
        return
    assert done.returncode == 1, said[-3000:]
    assert f"{out}: not written: no space left on the device (it needs at least" in said, said[-3000:]
    assert left == ["filler"]


def _read_only(tmp_path):
    """A folder made read-only in the task's namespace: (the folder, the listing file, the shell lines)."""
    folder = tmp_path / "ro"
    folder.mkdir()
    return folder, tmp_path / "listing.txt", f"mount --bind {folder} {folder}\nmount -o remount,bind,ro {folder}"


def test_a_read_only_folder_is_refused_before_any_work(blender, sphere, tmp_path):
    folder, listing, mounts = _read_only(tmp_path)
    out = folder / "sphere.ply"
    done = _in_namespace(blender, mounts, folder, listing, "-c", "tessera", "tessellate", sphere, "-o", out)
    said = done.stdout + done.stderr
    assert done.returncode == 1, said[-3000:]
    assert f"{out}: not written: the file system is read-only ({folder})" in said
    assert "Traceback" not in said and "tessellate 1/1" not in said  # refused before the work
    assert listing.read_text().split() == []


def test_a_summary_that_cannot_be_written_leaves_the_output_unwritten(blender, sphere, tmp_path):
    folder, listing, mounts = _read_only(tmp_path)
    out = tmp_path / "sphere.ply"
    done = _in_namespace(blender, mounts, folder, listing, "-c", "tessera", "tessellate", sphere, "-o", out,
                         "--json", folder / "summary.json")
    said = done.stdout + done.stderr
    assert done.returncode == 1, said[-3000:]
    assert f"{folder / 'summary.json'}: not written: the file system is read-only" in said
    assert "Traceback" not in said
    assert not out.exists() and not any(n.startswith(".sphere") for n in os.listdir(tmp_path))

"""`written.check_written` on files Blender's own exporters wrote (tier: blender): each whole file passes, and the
same file cut short anywhere (one byte, a block, half) or missing its last lines is caught, with what is missing."""

import os
import shutil

import pytest

pytestmark = pytest.mark.blender

#: Formats with a structural check: exporter, keyword arguments.
CHECKED = {
    ".stl": ("wm.stl_export", {"export_selected_objects": True}),
    ".stl-ascii": ("wm.stl_export", {"export_selected_objects": True, "ascii_format": True}),
    ".ply": ("wm.ply_export", {"export_selected_objects": True}),
    ".ply-ascii": ("wm.ply_export", {"export_selected_objects": True, "ascii_format": True}),
    ".ply-quads": ("wm.ply_export", {"export_selected_objects": True}),
    ".obj": ("wm.obj_export", {"export_selected_objects": True}),
    ".glb": ("export_scene.gltf", {"export_format": "GLB", "use_selection": True}),
    ".gltf": ("export_scene.gltf", {"export_format": "GLTF_SEPARATE", "use_selection": True}),
    ".blend": None,
}


@pytest.fixture
def written(addon_module):
    return addon_module("kernels.common.written")


@pytest.fixture
def files(addon_module):
    return addon_module("addon.command_line.files")


def _export(bpy, files, case, folder):
    ext = case.split("-")[0]
    path = str(folder / f"shape{ext}")
    if case == ".ply-quads":  # a mix of quads and triangles: the rows of the face list differ in length
        bpy.ops.mesh.primitive_cylinder_add(vertices=7)
    else:
        bpy.ops.mesh.primitive_uv_sphere_add(segments=24, ring_count=12)
    ob = bpy.context.active_object
    files.select_only([ob])
    if CHECKED[case] is None:
        bpy.ops.wm.save_as_mainfile(filepath=path, copy=True)
    else:
        op, kw = CHECKED[case]
        files._operator(op)(filepath=path, **kw)
    me = ob.data
    return path, {"vertices": len(me.vertices), "faces": len(me.polygons)}


@pytest.mark.parametrize("case", sorted(CHECKED))
def test_a_whole_file_passes_and_a_cut_one_does_not(written, files, clean_scene, bpy_module, tmp_path, case):
    path, expected = _export(bpy_module, files, case, tmp_path)
    written.check_written(path, expected)  # whole: no error
    size = os.path.getsize(path)
    whole = open(path, "rb").read()
    target = path
    if case == ".gltf":  # the .gltf's JSON is small; its buffer carries the data
        target = os.path.join(tmp_path, next(n for n in os.listdir(tmp_path) if n.endswith(".bin")))
        whole, size = open(target, "rb").read(), os.path.getsize(target)
    for cut in sorted({1, 7, 4096, size // 2, size - 90}):
        if not 0 < cut < size:
            continue
        with open(target, "wb") as f:
            f.write(whole[: size - cut])
        with pytest.raises(written.ShortWrite):
            written.check_written(path, expected)
    with open(target, "wb") as f:
        f.write(whole)
    written.check_written(path, expected)


def test_an_obj_missing_whole_lines_is_caught_by_its_counts(written, files, clean_scene, bpy_module, tmp_path):
    path, expected = _export(bpy_module, files, ".obj", tmp_path)
    lines = open(path, "rb").read().splitlines(keepends=True)
    with open(path, "wb") as f:
        f.writelines(lines[:-5])  # cut at a line's end: only the counts tell
    with pytest.raises(written.ShortWrite, match="faces"):
        written.check_written(path, expected)


def test_an_empty_file_is_never_whole(written, tmp_path):
    for ext in (".usdc", ".fbx", ".abc", ".ply"):
        (tmp_path / f"x{ext}").write_bytes(b"")
        with pytest.raises(written.ShortWrite, match="empty"):
            written.check_written(str(tmp_path / f"x{ext}"))
    shutil.rmtree(tmp_path)

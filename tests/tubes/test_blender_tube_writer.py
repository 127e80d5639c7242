"""The tube kernel writing straight into a new mesh's memory (`bridge.PolygonWriter`) (tier: blender)."""

import numpy as np
import pytest
from blender_helpers import select_only

pytestmark = pytest.mark.blender


def mesh_arrays(me):
    """Everything a tube mesh holds, read back through RNA."""
    out = {}
    for name, collection, prop, dtype, width in (
            ("co", me.vertices, "co", np.float32, 3), ("loop_start", me.polygons, "loop_start", np.int32, 1),
            ("loop_total", me.polygons, "loop_total", np.int32, 1), ("smooth", me.polygons, "use_smooth", bool, 1),
            ("material", me.polygons, "material_index", np.int32, 1),
            ("corner", me.loops, "vertex_index", np.int32, 1), ("corner_edge", me.loops, "edge_index", np.int32, 1),
            ("edge", me.edges, "vertices", np.int32, 2)):
        a = np.empty(len(collection) * width, dtype)
        collection.foreach_get(prop, a)
        out[name] = a
    if me.uv_layers:
        uv = np.empty(2 * len(me.loops), np.float32)
        me.uv_layers["UVMap"].data.foreach_get("uv", uv)
        out["uv"] = uv
    return out


def random_lines(polylines, seed, materials=True):
    rng = np.random.default_rng(seed)
    counts = rng.integers(2, 40, size=120)
    pts = np.cumsum(rng.normal(size=(counts.sum(), 3)), axis=0)
    return polylines.Polylines.build(pts, np.concatenate(([0], np.cumsum(counts))),
                                     radius=rng.uniform(0.1, 0.3, len(pts)), cyclic=rng.random(120) < 0.3,
                                     material_index=rng.integers(0, 3, 120) if materials else None)


@pytest.mark.parametrize("backend", ["numpy", "opencl"])
@pytest.mark.parametrize("caps,uvs,materials", [("NONE", False, False), ("NONE", True, True), ("FLAT", True, True),
                                                ("ROUND", False, True)])
def test_in_place_mesh_equals_the_copied_mesh(clean_scene, addon_module, backend, caps, uvs, materials):
    """Built into the new mesh's own arrays, the tubes are the mesh that building into numpy and copying gives:
    positions, faces, corners, edges, UVs, materials and sharp faces, the same bytes; the mesh validates clean; the
    arrays really were Blender's (their addresses are the items' own), and are let go of after `finish`."""
    if backend == "opencl":
        pytest.importorskip("pyopencl")
        if addon_module("kernels.tubes.opencl_path").runtime_for("auto") is None:
            pytest.skip("no OpenCL device with doubles")
    bridge = addon_module("addon.bridge")
    builder = addon_module("kernels.tubes.builder")
    lines = random_lines(addon_module("kernels.tubes.polylines"), 7, materials)
    settings = builder.TubeSettings(sides=7, caps=caps, uvs=uvs, point_normals=False)
    copied = bridge.write_polygons("copied", builder.build_tubes(lines, settings, backend=backend))

    writer = bridge.PolygonWriter("in_place")
    seen = {}

    def allocate(sizes, s):
        poly = writer.allocate(sizes, s)
        me = writer.mesh
        seen["positions"] = poly.positions.ctypes.data == me.attributes["position"].data[0].as_pointer()
        seen["corner_verts"] = poly.corner_verts.ctypes.data == me.attributes[".corner_vert"].data[0].as_pointer()
        seen["face_offsets"] = poly.face_offsets.ctypes.data == me.polygons[0].as_pointer()
        return poly

    poly = builder.build_tubes(lines, settings, backend=backend, allocate=allocate)
    in_place = writer.finish(poly)
    assert seen == {"positions": True, "corner_verts": True, "face_offsets": True}
    assert poly.positions is None and poly.face_offsets is None and poly.edges is None
    assert not in_place.validate(verbose=False)
    a, b = mesh_arrays(copied), mesh_arrays(in_place)
    assert a.keys() == b.keys() and ("uv" in a) == uvs
    for name in a:
        assert np.array_equal(a[name], b[name]), name
    assert np.any(a["material"]) == materials
    assert np.any(~a["smooth"]) == (caps == "FLAT")


def test_huge_pages_change_nothing_in_the_mesh(clean_scene, addon_module, monkeypatch):
    """A tube mesh large enough for huge pages (`kernels.common.huge_pages`), built in place with them asked for, is
    the bytes of the one built without; where the system offers them, the advice reached Blender's own arrays."""
    bridge = addon_module("addon.bridge")
    builder = addon_module("kernels.tubes.builder")
    huge_pages = addon_module("kernels.common.huge_pages")
    polylines = addon_module("kernels.tubes.polylines")
    rng = np.random.default_rng(5)
    counts = np.full(400, 100)
    pts = np.cumsum(rng.normal(scale=0.1, size=(counts.sum(), 3)), axis=0)
    lines = polylines.Polylines.build(pts, np.concatenate(([0], np.cumsum(counts))), radius=0.05)
    settings = builder.TubeSettings(sides=16, caps="ROUND", uvs=True, point_normals=False)
    meshes, flags = {}, {}
    for mode in ("off", "on"):
        monkeypatch.setenv("TESSERA_HUGE_PAGES", mode)
        writer = bridge.PolygonWriter(f"tubes_{mode}")

        def allocate(sizes, s, writer=writer, mode=mode):
            poly = writer.allocate(sizes, s)
            assert poly.corner_verts.nbytes > 2 * huge_pages.MIN_BYTES
            flags[mode] = huge_pages.vm_flags(poly.corner_verts.ctypes.data + poly.corner_verts.nbytes // 2)
            return poly

        meshes[mode] = mesh_arrays(writer.finish(builder.build_tubes(lines, settings, allocate=allocate)))
    assert meshes["on"].keys() == meshes["off"].keys()
    for name in meshes["on"]:
        assert np.array_equal(meshes["on"][name], meshes["off"][name]), name
    assert "hg" in flags["on"] or not huge_pages.thp_offered("/sys")


def test_face_offsets_in_place_are_read_back(clean_scene, bpy_module, addon_module):
    """`mesh_memory.face_offsets_view` is the whole (F + 1) offsets array on every supported Blender: offsets
    written through it are what RNA reads (starts and sizes), and `face_offsets_match` notices a wrong one."""
    bpy = bpy_module
    memory = addon_module("addon.mesh_memory")
    rng = np.random.default_rng(2)
    sizes = rng.integers(3, 7, 5000).astype(np.int32)
    offsets = np.concatenate(([0], np.cumsum(sizes))).astype(np.int32)
    me = bpy.data.meshes.new("offsets")
    me.vertices.add(8)
    me.loops.add(int(offsets[-1]))
    me.polygons.add(len(sizes))
    view = memory.face_offsets_view(me)
    assert view is not None and view.shape == (len(sizes) + 1,)
    view[:] = offsets
    del view
    assert memory.face_offsets_match(me, offsets)
    starts, totals = np.empty(len(sizes), np.int32), np.empty(len(sizes), np.int32)
    me.polygons.foreach_get("loop_start", starts)
    me.polygons.foreach_get("loop_total", totals)
    assert np.array_equal(starts, offsets[:-1]) and np.array_equal(totals, sizes)
    wrong = offsets.copy()
    wrong[-2] += 1
    assert not memory.face_offsets_match(me, wrong)
    bpy.data.meshes.remove(me)


def test_a_failure_after_the_mesh_was_handed_out_leaves_nothing(clean_scene, bpy_module, addon_module, monkeypatch):
    """The operator's kernel fails after it was given the new mesh's memory: a report, and no mesh left behind."""
    bpy = bpy_module
    builder = addon_module("kernels.tubes.builder")

    def broken(*args):
        raise ZeroDivisionError("simulated bug in the caps")

    monkeypatch.setattr(builder, "_write_caps", broken)
    curve = bpy.data.curves.new("Wire", "CURVE")
    spline = curve.splines.new("POLY")
    spline.points.add(2)
    spline.points.foreach_set("co", np.array([[0, 0, 0, 1], [1, 0, 0, 1], [1, 1, 0, 1]], np.float32).ravel())
    ob = bpy.data.objects.new("Wire", curve)
    bpy.context.scene.collection.objects.link(ob)
    select_only(bpy, ob)
    meshes = set(bpy.data.meshes)
    with pytest.raises(RuntimeError, match="simulated bug"):
        bpy.ops.tessera.tubes(caps="FLAT")
    assert set(bpy.data.meshes) == meshes
    assert "Wire.tubes" not in bpy.data.objects

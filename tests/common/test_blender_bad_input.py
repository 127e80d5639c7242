"""Bad input through the operators: every case ends in a clear message, the operator is cancelled and the
scene, images and maps are as they were (tier: blender). Each case names the words the message must contain.
"""

import numpy as np
import pytest
from blender_helpers import select_only, stroke_elements

pytestmark = pytest.mark.blender


def snapshot(bpy):
    """What an operator must not change when it refuses: every data block by name, and every image's pixels."""
    blocks = {name: sorted(b.name for b in getattr(bpy.data, name))
              for name in ("objects", "meshes", "images", "curves", "hair_curves", "materials")}
    pixels = {}
    for image in bpy.data.images:
        if image.size[0] * image.size[1]:
            px = np.empty(image.size[0] * image.size[1] * image.channels, np.float32)
            image.pixels.foreach_get(px)
            pixels[image.name] = px.tobytes()
    return blocks, pixels


def refused(bpy, op, words, **kw):
    """Run ``op`` expecting a refusal whose message contains every one of ``words``; the scene must not change."""
    before = snapshot(bpy)
    with pytest.raises(RuntimeError) as err:
        op(**kw)
    message = str(err.value)
    assert "Traceback" not in message
    for word in words:
        assert word.lower() in message.lower(), (word, message)
    assert snapshot(bpy) == before
    return message


def poly_curve(bpy, points, name="Curve"):
    data = bpy.data.curves.new(name, "CURVE")
    data.dimensions = "3D"
    if points is not None:
        spline = data.splines.new("POLY")
        spline.points.add(len(points) - 1)
        for p, co in zip(spline.points, points, strict=True):
            p.co = (*co, 1.0)
    ob = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(ob)
    return ob


@pytest.mark.parametrize("points, words", [
    ([(0, 0, 0)], ["no length"]),
    ([(1, 2, 3)] * 5, ["no length"]),
    (None, ["no points"]),
])
def test_tubes_from_curves_without_length(clean_scene, bpy_module, points, words):
    bpy = bpy_module
    ob = poly_curve(bpy, points)
    select_only(bpy, ob)
    refused(bpy, bpy.ops.tessera.tubes, words)


def test_tubes_from_hair_of_single_point_curves(clean_scene, bpy_module):
    bpy = bpy_module
    curves = bpy.data.hair_curves.new("Hair")
    curves.add_curves([1, 1, 1])
    ob = bpy.data.objects.new("Hair", curves)
    bpy.context.scene.collection.objects.link(ob)
    select_only(bpy, ob)
    refused(bpy, bpy.ops.tessera.tubes, ["no length"])


def test_tubes_keep_good_sources_and_name_the_empty_one(clean_scene, bpy_module):
    """A source with nothing to build does not cost the others their tubes; a source that is wrong cancels the
    whole run, and no tube of the other sources stays behind."""
    bpy = bpy_module
    good = poly_curve(bpy, [(0, 0, 0), (1, 0, 0), (1, 1, 0)], "Good")
    empty = poly_curve(bpy, None, "Empty")
    select_only(bpy, good, empty)
    assert bpy.ops.tessera.tubes(radius=0.1) == {"FINISHED"}
    assert "Good.tubes" in bpy.data.objects and "Empty.tubes" not in bpy.data.objects
    bpy.data.objects.remove(bpy.data.objects["Good.tubes"])
    wires = []
    for name in ("Thick", "Plain"):
        wire = bpy.data.meshes.new(name)
        wire.from_pydata([(0, 0, 0), (1, 0, 0), (1, 1, 0)], [(0, 1), (1, 2)], [])
        ob = bpy.data.objects.new(name, wire)
        bpy.context.scene.collection.objects.link(ob)
        wires.append(ob)
    wires[0].data.attributes.new("thickness", "FLOAT", "POINT")
    select_only(bpy, *wires)  # 'Plain' has no attribute 'thickness': an error, not an empty result
    refused(bpy, bpy.ops.tessera.tubes, ["thickness"], radius_source="ATTRIBUTE", attribute="thickness")
    assert "Thick.tubes" not in bpy.data.objects


def test_tubes_with_camera_sides_and_no_camera(clean_scene, bpy_module):
    bpy = bpy_module
    bpy.context.scene.camera = None
    ob = poly_curve(bpy, [(0, 0, 0), (1, 0, 0)])
    select_only(bpy, ob)
    message = refused(bpy, bpy.ops.tessera.tubes, ["camera sides", "scene camera"], sides_mode="CAMERA")
    assert "adaptive levels" not in message.lower()


def test_an_unexpected_failure_is_reported_and_nothing_is_left(clean_scene, bpy_module, addon_module, monkeypatch):
    """A bug inside an operator (here: the bridge failing after the first tube object was made) becomes a report
    saying nothing was changed, never an escaped traceback, and the tubes already placed are removed."""
    bpy = bpy_module
    tubes_op = addon_module("operators.tubes")
    a = poly_curve(bpy, [(0, 0, 0), (1, 0, 0)], "A")
    b = poly_curve(bpy, [(0, 1, 0), (1, 1, 0)], "B")
    real = tubes_op.bridge.PolygonWriter.finish
    calls = []

    def flaky(writer, poly):
        calls.append(writer.name)
        if len(calls) == 2:
            raise ZeroDivisionError("simulated bug")
        return real(writer, poly)

    monkeypatch.setattr(tubes_op.bridge.PolygonWriter, "finish", flaky)
    select_only(bpy, a, b)
    refused(bpy, bpy.ops.tessera.tubes, ["Tessera failed", "simulated bug", "nothing was changed"])
    assert len(calls) == 2  # the first tube was written, then removed with everything else
    assert not [m.name for m in bpy.data.meshes if m.name.endswith(".tubes")]  # both meshes, the failed one too


@pytest.mark.parametrize("make_error, words", [
    (lambda: MemoryError("Unable to allocate 183. MiB for an array with shape (24008000,) and data type float64"),
     ["Out of memory", "could not allocate 183 MiB", "nothing was changed", "memory budget"]),
])
def test_running_out_of_memory_anyway_is_named_and_nothing_is_left(clean_scene, bpy_module, addon_module,
                                                                   monkeypatch, make_error, words):
    """An allocation that fails although the estimate let the run start gives its own reason, not "Tessera failed".
    (The error is made inside the test: one kept by the parameters would keep the operator's frames, and with them
    Blender's data, alive past Blender's own exit, which then crashes 4.2 as it ends.)"""
    bpy = bpy_module
    tubes_op = addon_module("operators.tubes")
    ob = poly_curve(bpy, [(0, 0, 0), (1, 0, 0)], "A")

    def fails(*args, **kwargs):
        raise make_error()

    monkeypatch.setattr(tubes_op, "build_tubes", fails)
    select_only(bpy, ob)
    message = refused(bpy, bpy.ops.tessera.tubes, words)
    assert "Tessera failed" not in message


def test_a_run_larger_than_the_free_memory_is_refused_before_it_allocates(tmp_path):
    """Under an address-space limit (ulimit -v) and with no memory budget, Loop subdivision of a big grid is
    refused by the estimate, with the free memory in the message: the process neither aborts in PoCL nor fails in
    numpy."""
    import subprocess
    import sys

    from conftest import REPO_DIR, ROOT

    script = f"""
import resource, sys
sys.path[:0] = [{str(REPO_DIR)!r}, {str(ROOT / "tools")!r}]
import bpy
from source_tree import enable_extension
enable_extension({str(REPO_DIR)!r}, "lim")
bpy.context.preferences.addons["bl_ext.lim.tessera"].preferences.memory_budget_mb = 0
bpy.ops.mesh.primitive_grid_add(x_subdivisions=400, y_subdivisions=400)
from tessera.kernels.common.budget import _proc_kib
mapped = _proc_kib("/proc/self/status", "VmSize") * 1024
resource.setrlimit(resource.RLIMIT_AS, (mapped + 1536 * 2**20, resource.RLIM_INFINITY))
try:
    bpy.ops.tessera.loop_subdivide(levels=4)
    print("RESULT finished")
except RuntimeError as err:
    print("RESULT " + str(err).replace(chr(10), " "))
"""
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=600,
                          cwd=str(tmp_path))
    result = [line for line in proc.stdout.splitlines() if line.startswith("RESULT")]
    assert proc.returncode == 0 and result, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert "memory is free" in result[0] and "fewer levels" in result[0], result[0]


def _height_image(bpy, size=33):
    img = bpy.data.images.new("hm", size, size, float_buffer=True)
    px = np.zeros((size, size, 4), np.float32)
    px[..., 0] = np.linspace(0, 1, size)[None, :]
    img.pixels.foreach_set(px.ravel())
    return img


def test_terrain_the_camera_cannot_see(clean_scene, bpy_module):
    """The default camera (clip end 100 m) over a 36 km terrain sees no tile: a message that says what to
    change, and no empty Terrain object or mesh left behind."""
    bpy = bpy_module
    _height_image(bpy)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    bpy.context.scene.collection.objects.link(cam)
    cam.location = (0.0, 0.0, 30000.0)  # 30 km above, looking down, clip end 100 m
    bpy.context.scene.camera = cam
    refused(bpy, bpy.ops.tessera.terrain_add, ["sees no tile", "clip end", "frustum culling"], source="IMAGE",
            image_name="hm", texel_size=1125.0, tile_size=16)
    assert bpy.ops.tessera.terrain_add(source="IMAGE", image_name="hm", texel_size=1125.0, tile_size=16,
                                       culling=False) == {"FINISHED"}  # what the message suggests works


def _default_camera(bpy):
    """Blender's startup-file camera: 7 m from the origin, 5 m up, looking at it; clip end as new cameras have."""
    import math

    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    bpy.context.scene.collection.objects.link(cam)
    cam.location = (7.3589, -6.9258, 4.9583)
    cam.rotation_euler = (math.radians(63.6), 0.0, math.radians(46.7))
    bpy.context.scene.camera = cam
    return cam


def test_a_real_sized_dem_with_the_default_camera(clean_scene, bpy_module, tmp_path):
    """An SRTM-sized DEM (1201², 30 m texels: 36 km, 100 m to 1.1 km high) under the startup camera, which sits
    below its surface: a message that says what to change, and what it suggests gives a terrain."""
    import OpenImageIO as oiio

    bpy = bpy_module
    n = 1201
    y, x = np.mgrid[0:n, 0:n] / n
    h = 0.3 + 0.2 * np.sin(7 * x) * np.cos(5 * y) + 0.05 * np.random.default_rng(0).random((n, n))
    path = tmp_path / "dem.png"
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), oiio.ImageSpec(n, n, 1, "uint16")) and out.write_image((h * 65535).astype(np.uint16))
    out.close()
    cam = _default_camera(bpy)
    kw = dict(source="FILE", filepath=str(path), texel_size=30.0, height_scale=2000.0)
    refused(bpy, bpy.ops.tessera.terrain_add, ["sees no tile", "under its surface", "Frustum Culling"], **kw)
    cam.location.z = 1500.0  # above the heights, as suggested: within reach and looking down at it
    assert bpy.ops.tessera.terrain_add(**kw) == {"FINISHED"}
    assert len(bpy.context.active_object.data.polygons) > 0
    bpy.data.objects.remove(bpy.context.active_object)
    cam.location = (0.0, -80000.0, 3000.0)  # far away: the clip end is what to change, and by how much
    refused(bpy, bpy.ops.tessera.terrain_add, ["is 62,0", "beyond the camera's clip end", "Clip End past 62,0"], **kw)


def test_map_over_the_memory_budget_makes_nothing(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    bpy.ops.mesh.primitive_plane_add()
    prefs = addon_module("addon.preferences").get_preferences()
    old = prefs.memory_budget_mb
    prefs.memory_budget_mb = 64
    try:
        refused(bpy, bpy.ops.tessera.displacement_add, ["memory budget", "32768 x 32768"], width=32768, height=32768)
    finally:
        prefs.memory_budget_mb = old


@pytest.mark.opencl
def test_a_custom_kernel_writing_nan_changes_nothing_anywhere(clean_scene, bpy_module, addon_module, addon_opencl,
                                                              tmp_path):
    """Host map, device buffer, Blender image and an export are bit-identical before and after the refusal."""
    bpy = bpy_module
    maps = addon_module("addon.displacement.maps")
    bpy.ops.mesh.primitive_plane_add()
    ob = bpy.context.active_object
    assert bpy.ops.tessera.displacement_add(width=64, height=48) == {"FINISHED"}
    settings = ob.tessera.displacement
    state = maps.map_state(settings.image, maps.channels_for(settings))
    state.host[...] = np.random.default_rng(2).random(state.host.shape, np.float32)
    assert state.device is not None  # the add-on's own runtime has the device: the device half is checked
    state.device.push()
    state.to_image(settings.image)
    host = state.host.tobytes()
    first = tmp_path / "before.exr"
    assert bpy.ops.tessera.displacement_export(filepath=str(first)) == {"FINISHED"}
    text = bpy.data.texts.new("nan.cl")
    text.write("image = (float4)(NAN);")
    settings.kernel_text = text
    bpy.context.preferences.filepaths.use_scripts_auto_execute = True
    try:
        refused(bpy, bpy.ops.tessera.displacement_custom, ["NaN or infinite", "unchanged"])
    finally:
        bpy.context.preferences.filepaths.use_scripts_auto_execute = False
    assert state.host.tobytes() == host
    on_device = np.empty_like(state.host)
    state.device.runtime.cl.enqueue_copy(state.device.runtime.queue, on_device, state.device.buf)
    assert on_device.tobytes() == host
    second = tmp_path / "after.exr"
    assert bpy.ops.tessera.displacement_export(filepath=str(second)) == {"FINISHED"}
    from tessera.kernels.displacement.map_io import read_map

    assert read_map(str(first)).tobytes() == read_map(str(second)).tobytes()
    bpy.data.texts.remove(text)


def test_export_into_a_missing_folder_says_so(clean_scene, bpy_module, tmp_path):
    bpy = bpy_module
    bpy.ops.mesh.primitive_plane_add()
    assert bpy.ops.tessera.displacement_add(width=16, height=16) == {"FINISHED"}
    refused(bpy, bpy.ops.tessera.displacement_export, ["does not exist"],
            filepath=str(tmp_path / "missing" / "map.exr"))
    assert not (tmp_path / "missing").exists()


# --- numbers: every setting has a finite range, and NaN (which Blender does not clamp) is refused by name ------

def _float_props(rna):
    return [p for p in rna.properties if p.type == "FLOAT" and p.identifier != "rna_type"]


def _settings_groups(bpy):
    """Every Tessera property group (``Object/Scene/Image.tessera`` and the groups inside): (path, rna)."""
    found, todo = [], [(t, getattr(bpy.types, t).bl_rna.properties["tessera"].fixed_type)
                       for t in ("Object", "Scene", "Image")]
    while todo:
        path, rna = todo.pop()
        found.append((path, rna))
        todo += [(f"{path}.{p.identifier}", p.fixed_type) for p in rna.properties
                 if p.type == "POINTER" and p.identifier != "rna_type"
                 and getattr(p.fixed_type.base, "identifier", "") == "PropertyGroup"]
    return found


def test_every_numeric_setting_has_a_finite_range(clean_scene, bpy_module):
    """No float setting of an operator or a property group accepts 3e38: each has a hard range within the
    limits of `kernels.common.limits` (so the range in a refusal message means something)."""
    bpy = bpy_module
    structs = [(f"tessera.{name}", getattr(bpy.ops.tessera, name).get_rna_type()) for name in dir(bpy.ops.tessera)]
    structs += _settings_groups(bpy)
    assert len(structs) >= 13
    wide = [f"{where}.{p.identifier} [{p.hard_min:g}, {p.hard_max:g}]" for where, rna in structs
            for p in _float_props(rna) if not -1e15 <= p.hard_min <= p.hard_max <= 1e15]
    assert wide == []


def _setup_for(bpy, name, tmp_path):
    """Make the context ``tessera.<name>`` runs in; returns the keyword arguments it needs besides the NaN."""
    if name in ("tessellate", "displacement_add", "bake_lighting_hce", "impostor_bake"):
        bpy.ops.mesh.primitive_monkey_add()
        return {}
    if name == "tubes":
        select_only(bpy, poly_curve(bpy, [(0, 0, 0), (1, 0, 0), (1, 1, 0)]))
        return {}
    if name == "terrain_add":
        _height_image(bpy)
        return {"source": "IMAGE", "image_name": "hm"}
    if name in ("parametric_surface_add", "vector_field_texture"):  # need nothing selected
        return {}
    if name == "curve_adaptive":
        bpy.ops.curve.primitive_bezier_curve_add()
        return {}
    if name == "surface_tessellate":
        bpy.ops.surface.primitive_nurbs_surface_surface_add()
        bpy.context.active_object.data.splines[0].use_endpoint_u = True
        bpy.context.active_object.data.splines[0].use_endpoint_v = True
        return {}
    if name == "displacement_export":
        bpy.ops.mesh.primitive_plane_add()
        assert bpy.ops.tessera.displacement_add(width=16, height=16) == {"FINISHED"}
        return {"filepath": str(tmp_path / "map.png")}
    raise AssertionError(f"no setup for tessera.{name}: add one so its numeric settings are tried")


def test_nan_in_any_operator_setting_is_refused_by_name(clean_scene, bpy_module, tmp_path):
    bpy = bpy_module
    tried = 0
    for name in dir(bpy.ops.tessera):
        op = getattr(bpy.ops.tessera, name)
        props = _float_props(op.get_rna_type())
        if not props:
            continue
        kw = _setup_for(bpy, name, tmp_path)
        for p in props:
            value = float("nan") if not p.array_length else (float("nan"),) * p.array_length
            message = refused(bpy, op, [p.name, "must be a finite number between"], **kw, **{p.identifier: value})
            assert f"{p.hard_min:g} and {p.hard_max:g}" in message
            tried += 1
        for item in list(bpy.data.objects):
            bpy.data.objects.remove(item)
    assert tried >= 20, tried
    assert not (tmp_path / "map.png").exists()


def test_nan_in_object_and_brush_settings_is_refused_by_name(clean_scene, bpy_module, tmp_path):
    """Settings read from a property group (terrain bake, brush strokes, custom-kernel arguments, tessellate
    with the object's settings) are checked where they are read."""
    bpy = bpy_module
    _height_image(bpy)
    assert bpy.ops.tessera.terrain_add(source="IMAGE", image_name="hm", culling=False) == {"FINISHED"}
    terrain = bpy.context.active_object
    terrain.tessera.terrain.epsilon = float("nan")
    refused(bpy, bpy.ops.tessera.terrain_bake, ["Screen Error", "between 0.05 and 100000"])
    bpy.ops.mesh.primitive_monkey_add()
    monkey = bpy.context.active_object
    monkey.tessera.tessellate.near = float("nan")
    refused(bpy, bpy.ops.tessera.tessellate, ["Near", "between"], use_object_settings=True)
    bpy.ops.mesh.primitive_plane_add()
    assert bpy.ops.tessera.displacement_add(width=16, height=16) == {"FINISHED"}
    brush = bpy.context.scene.tessera.brush
    old = brush.radius
    brush.radius = float("nan")
    try:
        refused(bpy, bpy.ops.tessera.displacement_stroke, ["Radius", "between 0.5 and 100000"],
                stroke=stroke_elements([(4.0, 4.0, 1.0)]), map_space=True)
    finally:
        brush.radius = old


# --- degenerate inputs to every operator ------------------------------------------------------------------

def _mesh_object(bpy, name, verts, faces, edges=()):
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, list(edges), faces)
    ob = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(ob)
    select_only(bpy, ob)
    return ob


@pytest.mark.parametrize("verts, faces, edges, words", [
    ([], [], [], ["no faces"]),
    ([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [(0, 1)], ["no faces"]),
    ([(0, 0, 0), (1, 0, 0), (float("nan"), 0, 0)], [(0, 1, 2)], [], ["NaN"]),
])
def test_tessellate_empty_and_degenerate_meshes(clean_scene, bpy_module, verts, faces, edges, words):
    bpy = bpy_module
    _mesh_object(bpy, "Bad", verts, faces, edges)
    for op in (bpy.ops.tessera.tessellate, bpy.ops.tessera.loop_subdivide):
        for output in ("NEW_OBJECT", "REPLACE"):
            refused(bpy, op, words, output=output)


def test_loop_subdivide_refuses_non_manifold_edges_and_oversized_results(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    fin = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1)]
    _mesh_object(bpy, "Fins", fin, [(0, 1, 2), (1, 0, 3), (0, 1, 4)])
    for output in ("NEW_OBJECT", "REPLACE"):
        refused(bpy, bpy.ops.tessera.loop_subdivide, ["1 edge", "non-manifold"], output=output)
    bpy.ops.mesh.primitive_monkey_add()
    prefs = addon_module("addon.preferences").get_preferences()
    old = prefs.memory_budget_mb
    prefs.memory_budget_mb = 64
    try:
        refused(bpy, bpy.ops.tessera.loop_subdivide, ["3,964,928 triangles", "budget"], levels=6)
        engine = bpy.context.scene.render.engine
        prefs.memory_budget_mb = 4
        refused(bpy, bpy.ops.tessera.bake_lighting_hce, ["budget"], depth=4)
        assert bpy.context.scene.render.engine == engine and "tessera_hce" not in bpy.context.active_object.data
    finally:
        prefs.memory_budget_mb = old


@pytest.mark.parametrize("verts", [[(0, 0, 0), (1, 0, 0), (2, 0, 0)], [(0, 0, 0), (0, 0, 0), (0, 0, 0)],
                                   [(0, 0, 0), (1, 0, 0), (1e38, 1e38, 0)]])
def test_tessellate_degenerate_and_huge_triangles_give_finite_geometry(clean_scene, bpy_module, verts):
    """Collinear, collapsed and huge triangles are not errors (Blender's own modifiers take them): the result has
    the same faces as a regular triangle's, with finite positions and normals."""
    bpy = bpy_module
    counts = []
    for name, v in (("Regular", [(0, 0, 0), (1, 0, 0), (0, 1, 0)]), ("Odd", verts)):
        _mesh_object(bpy, name, v, [(0, 1, 2)])
        assert bpy.ops.tessera.loop_subdivide(levels=3) == {"FINISHED"}
        assert np.all(np.isfinite(np.array([p.co for p in bpy.context.active_object.data.vertices])))
        select_only(bpy, bpy.data.objects[name])
        assert bpy.ops.tessera.tessellate(level=4, method="PN") == {"FINISHED"}
        out = bpy.context.active_object.data
        co = np.empty(len(out.vertices) * 3, np.float32)
        out.vertices.foreach_get("co", co)
        normals = np.empty(len(out.loops) * 3, np.float32)
        out.corner_normals.foreach_get("vector", normals)
        assert np.isfinite(co).all() and np.isfinite(normals).all()
        counts.append(len(out.polygons))
    assert counts[0] == counts[1] > 1


def test_strokes_on_a_map_with_nan_texels_are_refused(clean_scene, bpy_module):
    bpy = bpy_module
    bpy.ops.mesh.primitive_plane_add()
    assert bpy.ops.tessera.displacement_add(width=16, height=16) == {"FINISHED"}
    image = bpy.context.active_object.tessera.displacement.image
    px = np.zeros(16 * 16 * 4, np.float32)
    px[4 * (16 * 8 + 8)] = np.nan
    image.pixels.foreach_set(px)
    image.update()
    refused(bpy, bpy.ops.tessera.displacement_stroke, ["NaN or infinite"],
            stroke=stroke_elements([(8.0, 8.0, 1.0)]), map_space=True)


@pytest.mark.parametrize("content, name, extra, words", [
    (b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\x00\x00", "cut.png", {}, ["cut.png"]),
    (b"not an image at all", "text.exr", {}, ["text.exr"]),
    (b"\x00" * 1001, "odd.r16", {}, ["1001 bytes", "odd"]),
    (b"\x00" * 1000, "wrong.r16", {"raw_width": 30, "raw_height": 30}, ["30", "1000 bytes"]),
    (None, "missing.png", {}, ["missing.png"]),
])
def test_terrain_from_broken_files(clean_scene, bpy_module, tmp_path, content, name, extra, words):
    bpy = bpy_module
    path = tmp_path / name
    if content is not None:
        path.write_bytes(content)
    message = refused(bpy, bpy.ops.tessera.terrain_add, words, source="FILE", filepath=str(path), **extra)
    assert not message.rstrip().endswith(":"), message  # a reason follows, not an empty string


def test_a_refusal_leaves_no_undo_step_and_survives_save_and_reload(clean_scene, bpy_module, tmp_path):
    """After a refused operator, undo takes back the user's last real step (the refusal made none), and the file
    saved after the refusal reloads with exactly the scene from before it."""
    bpy = bpy_module
    bpy.ops.mesh.primitive_cube_add()
    bpy.ops.ed.undo_push(message="cube")
    bpy.ops.mesh.primitive_monkey_add()
    bpy.ops.ed.undo_push(message="monkey")
    before = snapshot(bpy)
    refused(bpy, bpy.ops.tessera.tessellate, ["Level", "between"], level=float("nan"))
    path = tmp_path / "after_refusal.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    bpy.ops.ed.undo()
    assert "Suzanne" not in bpy.data.objects and "Cube" in bpy.data.objects
    bpy.ops.wm.open_mainfile(filepath=str(path))
    scene = {name: sorted(b.name for b in getattr(bpy.data, name)) for name in ("objects", "meshes")}
    assert scene == {name: before[0][name] for name in ("objects", "meshes")}  # orphans are not saved


def _live_surface(bpy, vertices):
    """A live parametric surface whose Control Points is a mesh of ``vertices``; returns (surface, points)."""
    assert bpy.ops.tessera.parametric_surface_add(output="LIVE") == {"FINISHED"}
    live = bpy.context.active_object
    me = bpy.data.meshes.new("Points")
    me.from_pydata(vertices, [], [])
    points = bpy.data.objects.new("Points", me)
    bpy.context.scene.collection.objects.link(points)
    live.tessera.surface.instance_object = points
    select_only(bpy, live)
    return live, points


@pytest.mark.parametrize("vertices, scale, words", [
    ([], 1.0, ["'Points'", "no vertices"]),
    ([(0, 0, 0), (float("nan"), 0, 0), (1, 1, 1)], 1.0, ["Vertex 1", "'Points'", "NaN"]),
    ([(0, 0, 0), (1, 0, 0)], 0.0, ["scaled to zero", "scale"]),
])
def test_live_surface_control_points_are_checked_by_name(clean_scene, bpy_module, vertices, scale, words):
    bpy = bpy_module
    live, _ = _live_surface(bpy, vertices)
    live.scale = (scale,) * 3
    bpy.context.view_layer.update()
    refused(bpy, bpy.ops.tessera.parametric_surface_bake, words)


def _bezier(bpy, middle):
    data = bpy.data.curves.new("Bent", "CURVE")
    data.dimensions = "3D"
    spline = data.splines.new("BEZIER")
    spline.bezier_points.add(2)
    for i, p in enumerate(spline.bezier_points):
        p.co, p.handle_left, p.handle_right = (i, 0, 0), (i - 0.3, 0.2, 0), (i + 0.3, -0.2, 0)
    spline.bezier_points[1].co = middle
    ob = bpy.data.objects.new("Bent", data)
    bpy.context.scene.collection.objects.link(ob)
    select_only(bpy, ob)
    return ob


@pytest.mark.parametrize("value", [float("nan"), float("inf"), 3e38])
def test_curve_points_at_nan_or_beyond_the_world_are_refused_where_they_enter(clean_scene, bpy_module, value):
    bpy = bpy_module
    _bezier(bpy, (value, 0.0, 0.0))
    refused(bpy, bpy.ops.tessera.curve_adaptive, ["Spline 0", "'Bent'", "point 1"])


def test_vector_field_grid_named_wrong_empty_or_no_active_object(clean_scene, bpy_module):
    bpy = bpy_module
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    bpy.context.scene.collection.objects.link(cam)
    bpy.context.scene.camera = cam
    cam.location = (0.0, -5.0, 1.0)
    bpy.context.view_layer.objects.active = None
    refused(bpy, bpy.ops.tessera.vector_field_texture, ["No object named 'Nope'"], field="MESH", field_object="Nope")
    empty = bpy.data.objects.new("Grid", bpy.data.meshes.new("Grid"))
    bpy.context.scene.collection.objects.link(empty)
    refused(bpy, bpy.ops.tessera.vector_field_texture, ["'Grid'", "no vertices"], field="MESH", field_object="Grid")
    before = set(bpy.data.images)
    assert bpy.ops.tessera.vector_field_texture(width=64, height=64) == {"FINISHED"}  # a camera and no active object
    # one image made (in background mode, making a GPU context can add Blender's own Render Result)
    assert [i.name for i in set(bpy.data.images) - before if i.type == "IMAGE"] == ["Vector Field"]


def test_a_foreign_hce_property_is_named_and_the_subdivision_still_runs(clean_scene, bpy_module):
    bpy = bpy_module
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=1)
    ob = bpy.context.active_object
    ob.data["tessera_hce"] = "not a bake"
    assert bpy.ops.tessera.loop_subdivide(levels=1) == {"FINISHED"}
    from tessera.kernels.common.errors import InvalidInputError
    from tessera.kernels.subdivision import hce

    with pytest.raises(InvalidInputError, match="holds a str"):
        hce.unpack_container("not a bake", np.zeros((1, 3), np.int32))


def test_a_nan_nailboard_setting_is_skipped_by_the_preview_and_named_by_the_panel(clean_scene, bpy_module,
                                                                                 addon_module):
    bpy = bpy_module
    bpy.ops.mesh.primitive_cube_add()
    s = bpy.context.active_object.tessera.nailboard
    s.tolerance = float("nan")
    preview = addon_module("addon.impostors.preview")
    assert not preview._finite(s)
    s.tolerance = 2.0
    assert preview._finite(s)


def test_adaptive_polylines_with_many_copies_are_refused_before_they_are_made(clean_scene, bpy_module):
    """200 splines at a tolerance their Max Segments cannot reach, 1,000 copies each: refused by the budget, with
    the points counted, before a copy is made; the same curve with a few copies is made."""
    bpy = bpy_module
    data = bpy.data.curves.new("Hair", "CURVE")
    data.dimensions = "3D"
    rng = np.random.default_rng(3)
    for _ in range(200):
        spline = data.splines.new("BEZIER")
        spline.bezier_points.add(3)
        for i, p in enumerate(spline.bezier_points):
            co = rng.normal(size=3) + (i, 0, 0)
            p.co, p.handle_left, p.handle_right = co, co + rng.normal(size=3), co + rng.normal(size=3)
    ob = bpy.data.objects.new("Hair", data)
    bpy.context.scene.collection.objects.link(ob)
    select_only(bpy, ob)
    refused(bpy, bpy.ops.tessera.curve_adaptive, ["points", "memory budget", "fewer Copies"], mode="TOLERANCE",
            tolerance=1e-9, max_segments=1024, copies=1000)
    assert bpy.ops.tessera.curve_adaptive(tolerance=1e-3, copies=3) == {"FINISHED"}
    made = bpy.context.active_object
    assert len(made.data.splines) == 600


def test_a_tolerance_max_segments_cannot_reach_says_where_and_by_how_much(clean_scene, bpy_module, capfd):
    bpy = bpy_module
    _bezier(bpy, (1.0, 2.0, 0.0))
    capfd.readouterr()
    assert bpy.ops.tessera.curve_adaptive(mode="TOLERANCE", tolerance=1e-6, max_segments=6) == {"FINISHED"}
    captured = capfd.readouterr()
    lines = (captured.out + captured.err).splitlines()
    line = next((line for line in lines if "over the tolerance" in line), lines)
    assert line.startswith("Warning") and "times over in spline 0" in line and "raise Max Segments" in line

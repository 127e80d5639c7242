"""Bad input through the operators: every case ends in a clear message, the operator is cancelled and the
scene, images and maps are as they were (tier: blender). Each case names the words the message must contain.
"""

import numpy as np
import pytest

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


def select(bpy, *obs):
    for other in bpy.context.selected_objects:
        other.select_set(False)
    for ob in obs:
        ob.select_set(True)
    bpy.context.view_layer.objects.active = obs[0]


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
    select(bpy, ob)
    refused(bpy, bpy.ops.tessera.tubes, words)


def test_tubes_from_hair_of_single_point_curves(clean_scene, bpy_module):
    bpy = bpy_module
    curves = bpy.data.hair_curves.new("Hair")
    curves.add_curves([1, 1, 1])
    ob = bpy.data.objects.new("Hair", curves)
    bpy.context.scene.collection.objects.link(ob)
    select(bpy, ob)
    refused(bpy, bpy.ops.tessera.tubes, ["no length"])


def test_tubes_keep_good_sources_and_name_the_empty_one(clean_scene, bpy_module):
    """A source with nothing to build does not cost the others their tubes; a source that is wrong cancels the
    whole run, and no tube of the other sources stays behind."""
    bpy = bpy_module
    good = poly_curve(bpy, [(0, 0, 0), (1, 0, 0), (1, 1, 0)], "Good")
    empty = poly_curve(bpy, None, "Empty")
    select(bpy, good, empty)
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
    select(bpy, *wires)  # 'Plain' has no attribute 'thickness': an error, not an empty result
    refused(bpy, bpy.ops.tessera.tubes, ["thickness"], radius_source="ATTRIBUTE", attribute="thickness")
    assert "Thick.tubes" not in bpy.data.objects


def test_tubes_with_camera_sides_and_no_camera(clean_scene, bpy_module):
    bpy = bpy_module
    bpy.context.scene.camera = None
    ob = poly_curve(bpy, [(0, 0, 0), (1, 0, 0)])
    select(bpy, ob)
    message = refused(bpy, bpy.ops.tessera.tubes, ["camera sides", "scene camera"], sides_mode="CAMERA")
    assert "adaptive levels" not in message.lower()


def test_an_unexpected_failure_is_reported_and_nothing_is_left(clean_scene, bpy_module, addon_module, monkeypatch):
    """A bug inside an operator (here: the bridge failing after the first tube object was made) becomes a report
    saying nothing was changed, never an escaped traceback, and the tubes already placed are removed."""
    bpy = bpy_module
    tubes_op = addon_module("operators.tubes")
    a = poly_curve(bpy, [(0, 0, 0), (1, 0, 0)], "A")
    b = poly_curve(bpy, [(0, 1, 0), (1, 1, 0)], "B")
    real = tubes_op.bridge.write_polygons
    calls = []

    def flaky(name, poly):
        calls.append(name)
        if len(calls) == 2:
            raise ZeroDivisionError("simulated bug")
        return real(name, poly)

    monkeypatch.setattr(tubes_op.bridge, "write_polygons", flaky)
    select(bpy, a, b)
    refused(bpy, bpy.ops.tessera.tubes, ["Tessera failed", "simulated bug", "nothing was changed"])
    assert len(calls) == 2  # the first tube was written, then removed with everything else


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
def test_a_custom_kernel_writing_nan_changes_nothing_anywhere(clean_scene, bpy_module, addon_module, opencl, tmp_path):
    """Host map, device buffer, Blender image and an export are bit-identical before and after the refusal."""
    bpy = bpy_module
    maps = addon_module("addon.displacement.maps")
    bpy.ops.mesh.primitive_plane_add()
    ob = bpy.context.active_object
    assert bpy.ops.tessera.displacement_add(width=64, height=48) == {"FINISHED"}
    settings = ob.tessera.displacement
    state = maps.map_state(settings.image, maps.channels_for(settings))
    state.host[...] = np.random.default_rng(2).random(state.host.shape, np.float32)
    if state.device is not None:
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
    if state.device is not None:
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

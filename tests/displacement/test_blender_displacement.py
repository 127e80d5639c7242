"""Displacement maps in Blender: map + Displace modifier, stroke replay, undo by serial, save/reload, EXR export,
custom-kernel trust (tier: blender; the OpenCL path runs when a device is present, numpy otherwise)."""

import numpy as np
import pytest
from blender_helpers import compat, refuses_tangent_space, stroke_elements

pytestmark = pytest.mark.blender
SIZE = 32


def make_plane(bpy, mode="HEIGHT"):
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=SIZE, y_subdivisions=SIZE, size=2)
    ob = bpy.context.active_object
    assert bpy.ops.tessera.displacement_add(width=SIZE, height=SIZE, mode=mode) == {"FINISHED"}
    return ob


def brush(bpy, **kw):
    b = bpy.context.scene.tessera.brush
    defaults = dict(kind="DRAW", radius=6.0, strength=0.25, falloff="SMOOTH", spacing=0.25, mirror_x=False,
                    use_pressure_strength=True, use_pressure_radius=False)
    for key, value in {**defaults, **kw}.items():
        setattr(b, key, value)
    return b


def replay(bpy, points, map_space=True):
    """Run the stroke operator on recorded elements: map texels (x, y, pressure) or surface points (x, y, z)."""
    stroke = stroke_elements(points, map_space)
    return bpy.ops.tessera.displacement_stroke(stroke=stroke, map_space=map_space)


def state_of(addon_module, ob):
    maps = addon_module("addon.displacement.maps")
    settings = ob.tessera.displacement
    return maps.map_state(settings.image, maps.channels_for(settings))


def image_rgba(image):
    w, h = image.size
    px = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(px)
    return px.reshape(h, w, 4)


def evaluated_z(bpy, ob):
    dg = bpy.context.evaluated_depsgraph_get()
    me = ob.evaluated_get(dg).to_mesh()
    z = np.array([v.co.z for v in me.vertices])
    ob.evaluated_get(dg).to_mesh_clear()
    return z


def test_map_modifier_shows_the_painted_height(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    ob = make_plane(bpy)
    mod = ob.modifiers["Tessera Displacement"]
    assert mod.direction == "NORMAL" and mod.texture.image == ob.tessera.displacement.image
    ob.tessera.displacement.strength = 2.0
    assert mod.strength == 2.0  # settings drive the modifier
    brush(bpy, radius=100.0, strength=0.3, falloff="CONSTANT")
    assert replay(bpy, [(16, 16, 1.0)]) == {"FINISHED"}
    state = state_of(addon_module, ob)
    assert np.all(state.host == np.float32(0.3))
    rgba = image_rgba(ob.tessera.displacement.image)
    assert np.all(rgba[..., :3] == np.float32(0.3)) and np.all(rgba[..., 3] == 1.0)
    assert np.allclose(evaluated_z(bpy, ob), 0.6, atol=1e-6)  # (0.3 - mid 0) * strength 2 along +Z


def test_replay_is_deterministic_and_undo_serial_restores_exact_bytes(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    results = []
    path = [(4, 5, 0.3), (12, 9, 1.0), (27, 20, 0.6)]
    for _ in range(2):
        ob = make_plane(bpy)
        brush(bpy, kind="NOISE", radius=7.0, strength=0.4, noise_cell=3.0)
        assert replay(bpy, path) == {"FINISHED"}
        results.append(state_of(addon_module, ob).host.copy())
    assert results[0].tobytes() == results[1].tobytes() and results[0].any()
    image = ob.tessera.displacement.image
    state = state_of(addon_module, ob)
    first = state.host.copy()
    brush(bpy, kind="SMOOTH", radius=9.0, strength=1.0)
    assert replay(bpy, [(10, 10, 1.0), (20, 12, 1.0)]) == {"FINISHED"}
    second = state.host.copy()
    assert image.tessera.serial == 2 and not np.array_equal(first, second)
    maps = addon_module("addon.displacement.maps")
    image.tessera.serial = 1  # what Blender's undo step holds after Ctrl+Z
    maps._on_undo_redo()
    assert state.host.tobytes() == first.tobytes()
    assert np.array_equal(image_rgba(image)[..., 0], first[..., 0])
    image.tessera.serial = 2  # redo
    maps._on_undo_redo()
    assert state.host.tobytes() == second.tobytes()
    image.tessera.serial = 0
    maps._on_undo_redo()
    assert not state.host.any()
    step = state.steps[2]
    assert step.nbytes == 2 * state.host.nbytes  # before and after of the one 64 x 64 tile this map fits in


def test_surface_locations_map_through_the_uvs(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    ob = make_plane(bpy)
    brush(bpy, kind="CONTACT", radius=1.5, strength=0.5)
    # the grid spans [-1, 1]; UV (u, v) = ((x + 1) / 2, (y + 1) / 2); texel = uv * 32 - 0.5
    assert replay(bpy, [(0.5 - 1 / 32, -0.5 - 1 / 32, 0.0)], map_space=False) == {"FINISHED"}
    host = state_of(addon_module, ob).host[..., 0]
    ys, xs = np.nonzero(host)
    assert (round(xs.mean()), round(ys.mean())) == (23, 7)
    assert np.all(host[ys, xs] == np.float32(-0.5))


def test_mirror_and_vector_maps(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    ob = make_plane(bpy, mode="VECTOR")
    assert ob.modifiers["Tessera Displacement"].direction == "RGB_TO_XYZ"
    brush(bpy, kind="DRAW", radius=4.0, strength=0.5, mirror_x=True, direction=(1.0, 0.0, 1.0))
    assert replay(bpy, [(5, 10, 1.0)]) == {"FINISHED"}
    m = state_of(addon_module, ob).host
    assert m.shape == (SIZE, SIZE, 3)
    assert np.allclose(m[..., 2], m[:, ::-1, 2], atol=1e-6) and np.allclose(m[..., 0], -m[:, ::-1, 0], atol=1e-6)


def test_bad_strokes_change_nothing(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    ob = make_plane(bpy)
    brush(bpy, kind="FORCE", strength=0.0)  # a force of zero radius is refused
    with pytest.raises(RuntimeError, match="radius"):
        replay(bpy, [(3, 3, 1.0)])
    assert not state_of(addon_module, ob).host.any() and ob.tessera.displacement.image.tessera.serial == 0


def test_export_and_import_round_trip(clean_scene, bpy_module, addon_module, tmp_path):
    bpy = bpy_module
    ob = make_plane(bpy)
    brush(bpy, kind="NOISE", radius=30.0, strength=1.0, noise_cell=2.0)
    replay(bpy, [(16, 16, 1.0)])
    path = str(tmp_path / "map.exr")
    assert bpy.ops.tessera.displacement_export(filepath=path) == {"FINISHED"}
    painted = state_of(addon_module, ob).host.copy()
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=4, y_subdivisions=4)
    other = bpy.context.active_object
    assert bpy.ops.tessera.displacement_add(filepath=path) == {"FINISHED"}
    assert state_of(addon_module, other).host.tobytes() == painted.tobytes()


@pytest.mark.opencl
def test_save_reload_is_exact_and_custom_kernels_need_trust(clean_scene, bpy_module, addon_module, tmp_path,
                                                           addon_opencl, monkeypatch):
    bpy = bpy_module
    custom = addon_module("operators.custom_kernel")
    map_edit = addon_module("kernels.displacement.map_edit")
    compiled = []  # every compile of a custom kernel, whichever module calls it
    for module in (custom, map_edit):
        real = module.compile_custom
        monkeypatch.setattr(module, "compile_custom", lambda *a, _real=real, **k: compiled.append(a) or _real(*a, **k))
    ob = make_plane(bpy)
    brush(bpy, kind="DRAW", radius=8.0, strength=0.7)
    replay(bpy, [(8, 8, 1.0), (24, 20, 0.5)])
    painted = state_of(addon_module, ob).host.copy()
    text = bpy.data.texts.new("kernel.cl")
    text.write("image.z += 1.0f;")
    ob.tessera.displacement.kernel_text = text
    prefs = bpy.context.preferences.filepaths
    prefs.use_scripts_auto_execute = False
    name = ob.name
    path = str(tmp_path / "painted.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    bpy.ops.wm.open_mainfile(filepath=path)
    assert compiled == []  # loading runs and compiles nothing
    ob = bpy.data.objects[name]
    bpy.context.view_layer.objects.active = ob
    image = ob.tessera.displacement.image
    assert image.packed_file is not None
    assert state_of(addon_module, ob).host.tobytes() == painted.tobytes()  # the packed EXR holds every bit
    with pytest.raises(RuntimeError, match="not trusted"):
        bpy.ops.tessera.displacement_custom()
    assert state_of(addon_module, ob).host.tobytes() == painted.tobytes()
    assert bpy.ops.tessera.displacement_trust_kernel("EXEC_DEFAULT") == {"FINISHED"}
    assert bpy.ops.tessera.displacement_custom() == {"FINISHED"}
    assert np.array_equal(state_of(addon_module, ob).host, painted + np.float32(1.0))
    assert len(compiled) == 1  # the counter sees a compile, so its empty reading after the load means none
    ob.tessera.displacement.kernel_text.from_string("image.z += ;")  # edited: a new source, and a broken one
    prefs.use_scripts_auto_execute = True
    before = state_of(addon_module, ob).host.copy()
    with pytest.raises(RuntimeError, match="failed to compile"):
        bpy.ops.tessera.displacement_custom()
    assert state_of(addon_module, ob).host.tobytes() == before.tobytes()
    prefs.use_scripts_auto_execute = False


def test_brush_cursor_sits_on_the_surface_with_the_brush_radius(clean_scene, bpy_module, addon_module):
    """The hover cursor's ring (the tool's gizmo and the stroke share it): centred where the ray meets the
    displaced surface, facing along its normal, radius = brush radius in texels × a texel's world size."""
    bpy = bpy_module
    cursor = addon_module("addon.displacement.brush_cursor")
    ob = make_plane(bpy)
    ob.location = (0.0, 0.0, 0.5)
    ob.scale = (2.0, 2.0, 2.0)
    bpy.context.view_layer.update()
    brush(bpy, radius=4.0)
    hit = cursor.surface_hit(bpy.context, ob, (0.3, -0.7, 10.0), (0.0, 0.0, -1.0))
    centre, normal, radius = hit.ring(4.0, (SIZE, SIZE), "")
    assert np.allclose(centre, (0.3, -0.7, 0.5), atol=1e-5)
    assert np.allclose(normal, (0, 0, 1), atol=1e-6)
    assert radius == pytest.approx(4.0 * 4.0 / SIZE, rel=1e-4)  # the plane is 4 m wide in the world: 32 texels
    points = cursor.ring_points(centre, normal, radius)
    assert np.allclose(np.linalg.norm(points - np.array(centre), axis=1), radius, rtol=1e-5)
    assert cursor.surface_hit(bpy.context, ob, (5.0, 5.0, 10.0), (0.0, 0.0, -1.0)) is None  # off the plane
    tool = addon_module("addon.displacement.brush_tool").TESSERA_TL_displacement_brush
    assert tool.bl_widget == cursor.TESSERA_GGT_brush_cursor.bl_idname
    assert all("bl_rna" in c.__dict__ for c in cursor.classes)  # registered with Blender


def evaluated_positions(bpy, ob):
    dg = bpy.context.evaluated_depsgraph_get()
    me = ob.evaluated_get(dg).to_mesh()
    co = np.empty(len(me.vertices) * 3)
    me.vertices.foreach_get("co", co)
    ob.evaluated_get(dg).to_mesh_clear()
    return co.reshape(-1, 3)


def tangent_reference(ob, values, mid, strength, ts):
    """Numpy reference of a tangent-space map on ``ob``'s mesh: each vertex's first corner gives the UV, the
    MikkTSpace tangent and bitangent sign (`Mesh.calc_tangents`, Blender's own entry point)."""
    me = ob.data
    me.calc_tangents(uvmap=me.uv_layers.active.name)
    n_loops = len(me.loops)
    loop_vert, tangent, sign = np.empty(n_loops, np.int64), np.empty(n_loops * 3), np.empty(n_loops)
    me.loops.foreach_get("vertex_index", loop_vert)
    me.loops.foreach_get("tangent", tangent)
    me.loops.foreach_get("bitangent_sign", sign)
    uv = np.empty(n_loops * 2)
    me.uv_layers.active.data.foreach_get("uv", uv)
    starts = np.empty(len(me.polygons), np.int64)
    me.polygons.foreach_get("loop_start", starts)
    first = np.full(len(me.vertices), n_loops)
    np.minimum.at(first, loop_vert, np.arange(n_loops))
    co, normals = np.empty(len(me.vertices) * 3), np.empty(len(me.vertices) * 3)
    me.vertices.foreach_get("co", co)
    me.vertices.foreach_get("normal", normals)
    uv = uv.reshape(-1, 2)
    # the group's sign (the face's UV orientation) is MikkTSpace's
    face_sign = ts.uv_orientation(uv, starts)
    loop_face = np.repeat(np.arange(len(starts)), np.diff(np.append(starts, n_loops)))
    assert np.array_equal(face_sign[loop_face], sign)
    sampled = ts.sample_linear(values, uv[first])
    offsets = ts.tangent_offsets(sampled, normals.reshape(-1, 3), tangent.reshape(-1, 3)[first], sign[first],
                                 mid, strength)
    return co.reshape(-1, 3) + offsets, sign


def set_map(image, values):
    rgba = np.ones((*values.shape[:2], 4), np.float32)
    rgba[..., :3] = values
    image.pixels.foreach_set(rgba.ravel())
    image.update()


def test_tangent_space_maps_displace_in_the_uv_frame(clean_scene, bpy_module, addon_module):
    """Tangent-space vector maps go through the geometry-nodes group: on a flat grid x, y, z of the map are
    the U tangent, bitangent and normal (mirrored UVs flip x only); on a UV sphere the group equals the numpy
    reference built on Blender's MikkTSpace (`calc_tangents`) for every vertex."""
    bpy = bpy_module
    ts = addon_module("kernels.displacement.tangent_space")
    nodes = addon_module("addon.displacement.nodes")
    if not compat().has_uv_tangent_node():  # before 5.0: the operator says what is needed, and makes nothing
        refuses_tangent_space(bpy, SIZE)
        return
    rng = np.random.default_rng(7)
    values = rng.uniform(-0.2, 0.2, (SIZE, SIZE, 3)).astype(np.float32)
    ob = make_plane(bpy, mode="VECTOR")
    settings = ob.tessera.displacement
    settings.space = "TANGENT"
    mod = ob.modifiers["Tessera Displacement"]
    assert mod.type == "NODES" and mod.node_group.name == nodes.GROUP_NAME and ob.modifiers[0] == mod
    settings.mid_level, settings.strength = 0.05, 2.0
    set_map(settings.image, values)
    expected, sign = tangent_reference(ob, values, 0.05, 2.0, ts)
    assert np.all(sign == 1.0)
    rest = np.array([v.co for v in ob.data.vertices])
    got = evaluated_positions(bpy, ob)
    assert np.allclose(got, expected, atol=1e-5)
    uv = np.array([d.uv for d in ob.data.uv_layers.active.data])
    first_uv = {}
    for loop in ob.data.loops:
        first_uv.setdefault(loop.vertex_index, uv[loop.index])
    plain = (ts.sample_linear(values, np.array([first_uv[i] for i in range(len(rest))])) - 0.05) * 2.0
    assert np.allclose(got - rest, plain, atol=1e-5)  # flat grid: (x, y, z) are X, Y, Z
    for d in ob.data.uv_layers.active.data:  # mirror the UVs in U
        d.uv = (1.0 - d.uv[0], d.uv[1])
    ob.data.update()
    expected, sign = tangent_reference(ob, values, 0.05, 2.0, ts)
    assert np.all(sign == -1.0)
    got = evaluated_positions(bpy, ob)
    assert np.allclose(got, expected, atol=1e-5)
    mirrored = (ts.sample_linear(values, np.array([(1.0 - first_uv[i][0], first_uv[i][1])
                                                    for i in range(len(rest))])) - 0.05) * 2.0
    assert np.allclose(got - rest, mirrored * [-1.0, 1.0, 1.0], atol=1e-5)
    settings.space = "LOCAL"  # back to the Displace modifier, in the same place in the stack
    assert ob.modifiers["Tessera Displacement"].type == "DISPLACE"

    bpy.ops.mesh.primitive_uv_sphere_add(segments=24, ring_count=12, radius=1.0)
    sphere = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    assert bpy.ops.tessera.displacement_add(width=SIZE, height=SIZE, mode="VECTOR", space="TANGENT") == {"FINISHED"}
    set_map(sphere.tessera.displacement.image, values)
    sphere.tessera.displacement.strength = 0.5
    expected, _ = tangent_reference(sphere, values, 0.0, 0.5, ts)
    got = evaluated_positions(bpy, sphere)
    assert np.allclose(got, expected, atol=2e-5)
    assert np.abs(got - np.array([v.co for v in sphere.data.vertices])).max() > 0.05


def test_live_painting_spends_at_most_a_quarter_of_its_time_writing_the_image(addon_module):
    """While painting, the map goes into the image every 50 ms at most, and only after three times as long as the
    last write took (writing a 4096² map into its image takes 18-75 ms: Blender has no partial pixel write)."""
    due = addon_module("operators.displacement").live_write_due
    assert due(0.051, 0.0, 0.0) and not due(0.049, 0.0, 0.0)
    assert not due(0.25, 0.0, 0.085) and due(0.26, 0.0, 0.085)
    assert due(10.26, 10.0, 0.085) and not due(10.2, 10.0, 0.085)


def test_each_stroke_writes_its_tiles_and_the_image_holds_the_whole_map(clean_scene, bpy_module, addon_module):
    """A stroke refreshes only the tiles it touched in the RGBA mirror it writes into the image: after strokes in
    different places (mirrored, on a map of many tiles, height and vector), and after undo, the image holds the
    whole map."""
    bpy = bpy_module
    maps = addon_module("addon.displacement.maps")
    for mode in ("HEIGHT", "VECTOR"):
        bpy.ops.mesh.primitive_grid_add(x_subdivisions=8, y_subdivisions=8, size=2)
        ob = bpy.context.active_object
        assert bpy.ops.tessera.displacement_add(width=300, height=200, mode=mode) == {"FINISHED"}
        image = ob.tessera.displacement.image
        brush(bpy, kind="DRAW", radius=9.0, strength=0.5, mirror_x=True)
        for path in ([(20, 30, 1.0), (60, 40, 1.0)], [(150, 170, 1.0)], [(250, 100, 0.5), (280, 20, 1.0)], None):
            if path is None:
                image.tessera.serial = 2  # undo the last stroke
                maps._on_undo_redo()
            else:
                assert replay(bpy, path) == {"FINISHED"}
            host = state_of(addon_module, ob).host
            px = image_rgba(image)
            assert np.array_equal(px[..., :3], np.broadcast_to(host, px[..., :3].shape)), (mode, path)
            assert (px[..., 3] == 1).all() and host.any()

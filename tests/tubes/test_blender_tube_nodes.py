"""The "Tessera Tubes" geometry-nodes group against the numpy tube builder (tier: blender): ring centres, radii and
frames on random open and closed curves and a helix, caps that close the tubes, the pixel clamp, UVs."""

import numpy as np
import pytest

pytestmark = pytest.mark.blender


def poly_curve(bpy, name, splines):
    """A Curve object of POLY splines: ``splines`` is a list of (points (n, 3), cyclic, radius (n,), tilt (n,))."""
    data = bpy.data.curves.new(name, "CURVE")
    data.dimensions = "3D"
    for points, cyclic, radius, tilt in splines:
        s = data.splines.new("POLY")
        s.points.add(len(points) - 1)
        s.points.foreach_set("co", np.c_[points, np.ones(len(points))].ravel())
        s.points.foreach_set("radius", radius)
        s.points.foreach_set("tilt", tilt)
        s.use_cyclic_u = cyclic
    ob = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def random_splines(rng, count=4):
    out = []
    for k in range(count):
        n = int(rng.integers(3, 40))
        steps = rng.normal(size=(n, 3)) * 0.3 + np.array([0.4, 0.0, 0.0])
        points = np.cumsum(steps, axis=0)
        out.append((points, k % 2 == 1, rng.uniform(0.5, 2.0, n), rng.uniform(-1.0, 1.0, n)))
    turns = np.linspace(0, 6 * np.pi, 120)
    helix = np.c_[np.cos(turns), np.sin(turns), 0.05 * turns]
    out.append((helix, False, np.ones(len(turns)), np.zeros(len(turns))))
    ring = np.linspace(0, 2 * np.pi, 50, endpoint=False)
    knot = np.c_[np.sin(ring) + 2 * np.sin(2 * ring), np.cos(ring) - 2 * np.cos(2 * ring), -np.sin(3 * ring)]
    out.append((knot, True, np.ones(len(ring)), np.zeros(len(ring))))  # a closed, non-planar trefoil: seam twist
    return out


def tube_modifier(bpy, addon_module, ob, **inputs):
    ng = addon_module("addon.node_groups")
    spec = addon_module("addon.tubes.nodes").SPEC
    mod = ob.modifiers.new(spec.name, "NODES")
    mod.node_group = ng.ensure_group(spec)
    ng.set_inputs(mod, inputs)
    return mod


def evaluated(bpy, ob):
    me = ob.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
    pos = np.empty(len(me.vertices) * 3, np.float32)
    me.attributes["position"].data.foreach_get("vector", pos)
    return pos.reshape(-1, 3).astype(np.float64), me


def kernel_tubes(addon_module, ob, radius, **settings):
    bridge = addon_module("addon.curve_bridge")
    builder = addon_module("kernels.tubes.builder")
    lines, _ = bridge.read_curve_object(ob, radius)
    return lines, builder.build_tubes(lines, builder.TubeSettings(**settings), backend="numpy")


@pytest.mark.parametrize("seed", [0, 1])
def test_rings_equal_the_kernels_frames(clean_scene, bpy_module, addon_module, seed):
    bpy = bpy_module
    ob = poly_curve(bpy, "Wires", random_splines(np.random.default_rng(seed)))
    tube_modifier(bpy, addon_module, ob, Radius=0.05, Sides=8)
    pos, me = evaluated(bpy, ob)
    lines, mesh = kernel_tubes(addon_module, ob, 0.05, sides=8, caps="NONE")
    assert pos.shape == mesh.positions.shape
    scale = np.abs(mesh.positions).max()
    # same vertices in the same order: ring k of curve c, side j, from cos/sin of 2πj/n on the kernel's frames
    assert np.abs(pos - mesh.positions).max() <= 1e-5 * scale
    # ring centres, radii and frames (N from the ring's first vertex): float32 positions of magnitude ~10 around
    # rings of radius ~0.05 limit how closely a frame can be read back to ~2e-5
    frames = addon_module("kernels.tubes.frames")
    rings = pos.reshape(-1, 8, 3)
    centre = rings.mean(axis=1)
    assert np.allclose(centre, lines.points, atol=1e-5 * scale)
    radial = rings[:, 0] - centre
    radius = np.linalg.norm(radial, axis=1)
    assert np.allclose(radius, lines.radius, rtol=1e-3)
    _, n_ref, _ = frames.rotation_minimizing_frames(lines)
    assert np.abs(radial / radius[:, None] - n_ref).max() < 1e-4
    # corner UVs: per face, the same (vertex, u, v) as the kernel's
    uv = np.empty(len(me.loops) * 2, np.float32)
    me.attributes["UVMap"].data.foreach_get("vector", uv)
    corner_verts = np.empty(len(me.loops), np.int32)
    me.attributes[".corner_vert"].data.foreach_get("value", corner_verts)
    ours = np.c_[corner_verts, uv.reshape(-1, 2)].reshape(-1, 4, 3)
    theirs = np.c_[mesh.corner_verts, mesh.corner_uvs].reshape(-1, 4, 3)
    order = np.argsort(ours[:, :, 0], axis=1)
    ours = np.take_along_axis(ours, order[:, :, None], axis=1)
    theirs = np.take_along_axis(theirs, np.argsort(theirs[:, :, 0], axis=1)[:, :, None], axis=1)
    assert np.array_equal(ours[:, :, 0], theirs[:, :, 0])
    assert np.abs(ours[:, :, 1:] - theirs[:, :, 1:]).max() < 1e-5
    ob.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh_clear()


def test_pixel_clamp_keeps_one_pixel_for_the_active_camera(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    cameras = addon_module("addon.cameras")
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 400, 300, 100
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    scene.collection.objects.link(cam)
    cam.location, cam.rotation_euler = (3.0, -14.0, 4.0), (1.3, 0.0, 0.2)
    scene.camera = cam
    ob = poly_curve(bpy, "Wires", random_splines(np.random.default_rng(5)))
    ob.location, ob.rotation_euler = (0.5, 1.0, -0.3), (0.1, 0.2, 0.3)
    bpy.context.view_layer.update()
    tube_modifier(bpy, addon_module, ob, Radius=0.001, Sides=6, **{
        "Pixel Clamp": True, "Field of View": cam.data.angle_x, "Image Width": 400})
    pos, me = evaluated(bpy, ob)
    camera = cameras.object_camera(cameras.scene_camera(bpy.context), ob.matrix_world)
    lines, _ = addon_module("addon.curve_bridge").read_curve_object(ob, 0.001)
    builder = addon_module("kernels.tubes.builder")
    mesh = builder.build_tubes(lines, builder.TubeSettings(sides=6, aa_clamp=True), camera=camera, backend="numpy")
    radius = np.linalg.norm(pos.reshape(-1, 6, 3) - lines.points[:, None, :], axis=2).mean(axis=1)
    assert radius.min() > 0.001 * 1.5  # the clamp is active along the whole tube
    assert np.abs(pos - mesh.positions).max() <= 1e-5 * np.abs(mesh.positions).max()
    ob.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh_clear()


@pytest.mark.parametrize("caps", ["Flat", "Round"])
def test_caps_close_open_tubes_like_the_kernel(clean_scene, bpy_module, addon_module, caps):
    bpy = bpy_module
    ob = poly_curve(bpy, "Wires", random_splines(np.random.default_rng(3), count=3))
    tube_modifier(bpy, addon_module, ob, Radius=0.05, Sides=8, Caps=caps)
    pos, me = evaluated(bpy, ob)
    _, mesh = kernel_tubes(addon_module, ob, 0.05, sides=8, caps=caps.upper())
    assert len(me.vertices) == len(mesh.positions) and len(me.polygons) == len(mesh.face_sizes)
    corner_edge = np.empty(len(me.loops), np.int32)
    me.attributes[".corner_edge"].data.foreach_get("value", corner_edge)
    assert np.all(np.bincount(corner_edge, minlength=len(me.edges)) == 2)  # closed and manifold
    # the same points as the kernel's (caps are numbered differently): nearest neighbours coincide
    ref = mesh.positions.astype(np.float64)
    d = np.linalg.norm(pos[:, None, :] - ref[None, :, :], axis=2).min(axis=1)
    assert d.max() <= 1e-5 * np.abs(ref).max()
    ob.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh_clear()


@pytest.mark.parametrize("primitive", ["bezier_curve", "bezier_circle", "nurbs_path"])
def test_smooth_curves_are_swept_at_their_evaluated_points(clean_scene, bpy_module, addon_module, primitive):
    bpy = bpy_module
    getattr(bpy.ops.curve, f"primitive_{primitive}_add")()
    ob = bpy.context.active_object
    tube_modifier(bpy, addon_module, ob, Radius=0.1, Sides=12)
    pos, me = evaluated(bpy, ob)
    _, mesh = kernel_tubes(addon_module, ob, 0.1, sides=12, caps="NONE")
    assert pos.shape == mesh.positions.shape
    assert np.abs(pos - mesh.positions).max() <= 1e-5 * np.abs(mesh.positions).max()
    ob.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh_clear()

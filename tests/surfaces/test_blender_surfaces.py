"""``tessera.parametric_surface_add`` (tier: blender): the mesh Blender holds is the kernel's welded surface (the
same positions, triangles and UVs), closed where the surface closes, at the 3D cursor; bad parameters change
nothing."""

import dataclasses

import numpy as np
import pytest
from blender_helpers import select_only

pytestmark = pytest.mark.blender


def mesh_arrays(me):
    pos = np.empty(len(me.vertices) * 3, np.float32)
    me.attributes["position"].data.foreach_get("vector", pos)
    verts = np.empty(len(me.loops), np.int32)
    me.attributes[".corner_vert"].data.foreach_get("value", verts)
    uv = np.empty(len(me.loops) * 2, np.float32)
    me.attributes["UVMap"].data.foreach_get("vector", uv)
    edges = np.empty(len(me.loops), np.int32)
    me.attributes[".corner_edge"].data.foreach_get("value", edges)
    return pos.reshape(-1, 3), verts.reshape(-1, 3), uv.reshape(-1, 3, 2), edges


@pytest.mark.parametrize("kind,closed", [("SPHERE", True), ("CONE", False), ("TORUS", True), ("STEINER", True),
                                         ("KLEIN", True), ("MOBIUS", False), ("TREFOIL", True),
                                         ("SUPERELLIPSOID", True)])
def test_the_baked_mesh_is_the_kernels_surface(clean_scene, bpy_module, addon_module, kind, closed):
    bpy = bpy_module
    parametric = addon_module("kernels.surfaces.parametric")
    domain_mesh = addon_module("kernels.surfaces.domain_mesh")
    bpy.context.scene.cursor.location = (1.0, 2.0, 3.0)
    try:
        assert bpy.ops.tessera.parametric_surface_add(surface=kind, factor=12) == {"FINISHED"}
    finally:
        bpy.context.scene.cursor.location = (0.0, 0.0, 0.0)  # later tests add objects at the cursor
    ob = bpy.context.active_object
    assert tuple(ob.location) == (1.0, 2.0, 3.0) and ob.select_get()
    cls = parametric.SURFACES[kind]  # the options' defaults are the kernel's, kept by Blender as float32
    shape = {f.name: float(np.float32(f.default)) for f in dataclasses.fields(cls)}
    want = domain_mesh.surface_mesh(cls(**shape), 12)
    pos, tris, uv, edges = mesh_arrays(ob.data)
    assert np.array_equal(pos, want.positions) and np.array_equal(tris, want.triangles)
    assert np.array_equal(uv, want.uvs)
    uses = np.bincount(edges, minlength=len(ob.data.edges))
    assert uses.max() == 2 and ((uses == 1).sum() == 0) == closed
    assert all(p.use_smooth for p in ob.data.polygons)


def test_shape_parameters_reach_the_surface(clean_scene, bpy_module):
    bpy = bpy_module
    assert bpy.ops.tessera.parametric_surface_add(surface="TORUS", factor=16, torus_major=3.0,
                                                  torus_minor=0.25) == {"FINISHED"}
    pos, _, _, _ = mesh_arrays(bpy.context.active_object.data)
    x, y, z = pos.astype(np.float64).T
    assert np.abs((np.hypot(x, y) - 3.0) ** 2 + z * z - 0.0625).max() < 1e-5


def test_a_bad_parameter_adds_nothing(clean_scene, bpy_module):
    bpy = bpy_module
    before = (len(bpy.data.objects), len(bpy.data.meshes))
    with pytest.raises(RuntimeError, match="Radius must be a finite number"):
        bpy.ops.tessera.parametric_surface_add(surface="SPHERE", sphere_radius=float("nan"))
    assert (len(bpy.data.objects), len(bpy.data.meshes)) == before


@pytest.mark.parametrize("surface", ["SPHERE", "TORUS", "KLEIN", "MOBIUS"])
def test_a_factor_that_leaves_no_triangle_is_refused_with_what_to_change(clean_scene, bpy_module, surface):
    """Factor 1 (0 is clamped to it): every triangle folds onto a seam; refused, nothing added, no internal error."""
    bpy = bpy_module
    before = (len(bpy.data.objects), len(bpy.data.meshes))
    for factor in (0, 1):
        with pytest.raises(RuntimeError) as err:
            bpy.ops.tessera.parametric_surface_add(surface=surface, factor=factor)
        assert "use a Factor of 2 or more" in str(err.value) and "Tessera failed" not in str(err.value)
    assert (len(bpy.data.objects), len(bpy.data.meshes)) == before
    assert bpy.ops.tessera.parametric_surface_add(surface=surface, factor=2) == {"FINISHED"}


def bezier_object(bpy, co, hl, hr, cyclic=False, radius=None):
    data = bpy.data.curves.new("Bez", "CURVE")
    data.dimensions = "3D"
    s = data.splines.new("BEZIER")
    s.bezier_points.add(len(co) - 1)
    s.bezier_points.foreach_set("co", np.asarray(co, np.float32).ravel())
    s.bezier_points.foreach_set("handle_left", np.asarray(hl, np.float32).ravel())
    s.bezier_points.foreach_set("handle_right", np.asarray(hr, np.float32).ravel())
    if radius is not None:
        s.bezier_points.foreach_set("radius", np.asarray(radius, np.float32))
    s.use_cyclic_u = cyclic
    ob = bpy.data.objects.new("Bez", data)
    bpy.context.scene.collection.objects.link(ob)
    select_only(bpy, ob)
    return ob


def poly_points(ob):
    out = []
    for s in ob.data.splines:
        co = np.empty(len(s.points) * 4, np.float32)
        s.points.foreach_get("co", co)
        r = np.empty(len(s.points), np.float32)
        s.points.foreach_get("radius", r)
        out.append((co.reshape(-1, 4)[:, :3], r, s.use_cyclic_u, s.type))
    return out


@pytest.mark.parametrize("cyclic", [False, True])
def test_curve_to_adaptive_polyline_samples_where_it_bends(clean_scene, bpy_module, addon_module, cyclic):
    bpy = bpy_module
    bz = addon_module("kernels.common.curves.bezier_curves")
    co = np.array([[0, 0, 0], [4, 0, 0], [4.2, 0.3, 0], [8, 3, 1]], np.float32)  # straight, then a sharp bend
    hl = co - np.array([[1, 0, 0], [1, 0, 0], [0, -3, 0], [1, 1, 0]], np.float32)
    hr = co + np.array([[1, 0, 0], [1, 0, 0], [0, -3, 0], [1, 1, 0]], np.float32)
    src = bezier_object(bpy, co, hl, hr, cyclic, radius=[1, 2, 3, 4])
    assert bpy.ops.tessera.curve_adaptive() == {"FINISHED"}
    out = bpy.context.active_object
    assert out is not src and out.type == "CURVE" and out.matrix_world == src.matrix_world
    [(pts, radius, out_cyclic, kind)] = poly_points(out)
    assert kind == "POLY" and out_cyclic == cyclic
    control = bz.segment_controls(co, hl, hr, cyclic)
    counts = bz.curvature_counts(control)
    assert counts[0] == 6 and counts.max() == 32  # the straight segment gets the minimum, the bend the cap
    want = bz.sample(control, counts, cyclic)
    assert np.allclose(pts, want.points, atol=1e-5)
    assert radius[0] == 1 and radius[counts[0]] == 2


def test_curve_copies_and_bad_splines(clean_scene, bpy_module):
    bpy = bpy_module
    co = np.array([[0, 0, 0], [2, 1, 0]], np.float32)
    bezier_object(bpy, co, co - [0.5, 0, 0], co + [0.5, 0, 0])
    assert bpy.ops.tessera.curve_adaptive(copies=6, copy_offset=(0, 0, 0.6)) == {"FINISHED"}
    polys = poly_points(bpy.context.active_object)
    assert len(polys) == 6
    assert np.allclose(polys[5][0] - polys[0][0], [0, 0, 0.5], atol=1e-6)
    # a curve with a one-point spline, or a NURBS spline of order above its points: refused, nothing added
    data = bpy.data.curves.new("Nurbs", "CURVE")
    s = data.splines.new("NURBS")
    ob = bpy.data.objects.new("Nurbs", data)
    bpy.context.scene.collection.objects.link(ob)
    bpy.context.view_layer.objects.active = ob
    before = len(bpy.data.objects), len(bpy.data.curves)
    with pytest.raises(RuntimeError, match="Spline 0 of 'Nurbs' has a single point"):
        bpy.ops.tessera.curve_adaptive()
    s.points.add(3)
    s.points.foreach_set("co", np.array([[0, 0, 0, 1], [1, 0, 0, -1], [1, 1, 0, 1], [0, 1, 0, 1]], np.float32).ravel())
    with pytest.raises(RuntimeError, match="NURBS spline 0 has control points or weights|weights of zero or less"):
        bpy.ops.tessera.curve_adaptive()
    assert (len(bpy.data.objects), len(bpy.data.curves)) == before


def test_tessellate_surface_on_the_teapot(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    bp = addon_module("kernels.surfaces.bezier_patches")
    nurbs = addon_module("kernels.common.curves.nurbs")
    from tools.revolved_teapot import teapot_patches
    from tools.surface_objects import write_surface_patches

    patches, names = teapot_patches()
    ob = write_surface_patches(patches)
    assert len(ob.data.splines) == 24
    surfaces, rows = addon_module("addon.curve_bridge").read_surface_splines(ob.data)
    assert rows == [] and len(surfaces) == 24
    read = nurbs.patches_of([s for _, s in surfaces]).patches
    assert np.allclose(bp.cartesian(read), patches.astype(np.float32)) and np.all(read[..., 3] == 1)
    assert bpy.ops.tessera.surface_tessellate(metrics={"CURVATURE"}) == {"FINISHED"}
    out = bpy.context.active_object
    edges = bp.patch_edges(read)
    el, inner = bp.patch_levels(read, edges, bp.PatchLod())
    want = bp.tessellate_patches(read, el, inner, edges)
    pos, tris, uv, corner_edges = mesh_arrays(out.data)
    assert np.array_equal(pos, want.positions) and np.array_equal(tris, want.triangles)
    assert np.allclose(uv, want.corner_uv)  # one spline per patch: its UVs are the patch's own
    uses = np.bincount(corner_edges, minlength=len(out.data.edges))
    assert uses.max() == 2  # welded: only the rim's and the lid's open circles are boundary
    c = bp.cartesian(edges.control)
    assert (uses == 1).sum() == sum(int(el[e]) for e in range(len(c)) if np.allclose(c[e, :, 2], 2.4)
                                    and np.isclose(np.hypot(*c[e, 0, :2]), (1.3, 1.4)).any())
    # distance levels for the scene camera: near -> finer than far
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    bpy.context.scene.collection.objects.link(cam)
    bpy.context.scene.camera = cam
    for metrics in ({"DISTANCE"}, {"EDGE_LENGTH"}):
        counts = []
        for y in (-3.0, -60.0):
            cam.location, cam.rotation_euler = (0.0, y, 1.5), (1.5708, 0.0, 0.0)
            bpy.context.view_layer.objects.active = ob
            assert bpy.ops.tessera.surface_tessellate(metrics=metrics, near=2.0, far=50.0) == {"FINISHED"}
            counts.append(len(bpy.context.active_object.data.polygons))
        assert counts[0] > 4 * counts[1], metrics


def test_tessellate_surface_refuses_what_blender_cannot_draw(clean_scene, bpy_module):
    bpy = bpy_module
    bpy.ops.surface.primitive_nurbs_surface_torus_add()  # order 3, 8 points, Bézier knots
    bpy.context.active_object.data.splines[0].order_u = 4  # 8 points do not make order-4 Bézier spans
    before = len(bpy.data.objects), len(bpy.data.meshes)
    with pytest.raises(RuntimeError, match="surface spline 0 has Bézier knots that need 1 more point"):
        bpy.ops.tessera.surface_tessellate()
    assert (len(bpy.data.objects), len(bpy.data.meshes)) == before


def test_bake_surface_refuses_a_control_object_that_is_not_a_mesh(clean_scene, bpy_module):
    bpy = bpy_module
    assert bpy.ops.tessera.parametric_surface_add(surface="SPHERE", output="LIVE") == {"FINISHED"}
    live = bpy.context.active_object
    bpy.ops.curve.primitive_bezier_curve_add()
    live.tessera.surface.instance_object = bpy.context.active_object
    bpy.context.view_layer.objects.active = live
    before = len(bpy.data.meshes)
    with pytest.raises(RuntimeError, match="Control Points must be a mesh"):
        bpy.ops.tessera.parametric_surface_bake()
    assert len(bpy.data.meshes) == before
    with pytest.raises(RuntimeError, match="Radius must be a finite number"):
        bpy.ops.tessera.parametric_surface_add(surface="SPHERE", output="LIVE", sphere_radius=float("nan"))

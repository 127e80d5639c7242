"""``tessera.tubes`` on real curve, hair and wire-mesh objects (tier: blender)."""

import numpy as np
import pytest
from blender_helpers import select_only

pytestmark = pytest.mark.blender


def mesh_arrays(me):
    n_v, n_c, n_e = len(me.vertices), len(me.loops), len(me.edges)
    pos = np.empty(n_v * 3, np.float32)
    me.attributes["position"].data.foreach_get("vector", pos)
    corner_edge = np.empty(n_c, np.int32)
    me.attributes[".corner_edge"].data.foreach_get("value", corner_edge)
    return pos.reshape(-1, 3), np.bincount(corner_edge, minlength=n_e)


def run_tubes(bpy, ob, **kw):
    select_only(bpy, ob)
    assert bpy.ops.tessera.tubes(**kw) == {"FINISHED"}
    return bpy.context.active_object


def test_bezier_curve_gives_a_closed_valid_mesh_with_the_point_radius(clean_scene, bpy_module):
    bpy = bpy_module
    bpy.ops.curve.primitive_bezier_curve_add(location=(1, 2, 3))
    ob = bpy.context.active_object
    pts = ob.data.splines[0].bezier_points
    pts[0].radius, pts[1].radius = 1.0, 2.0
    ob.data.materials.append(bpy.data.materials.new("Wire"))
    res = ob.data.resolution_u
    out = run_tubes(bpy, ob, radius=0.05, sides=8, caps="FLAT")
    me = out.data
    assert out.name == f"{ob.name}.tubes" and me.materials[0].name == "Wire"
    assert np.allclose(np.array(out.matrix_world), np.array(ob.matrix_world))
    assert len(me.vertices) == (res + 1) * 8 and len(me.polygons) == res * 8 + 2
    assert not me.validate(verbose=False)  # edges written by the kernel need no fixing
    pos, use = mesh_arrays(me)
    assert np.all(use == 2)  # closed and manifold
    rings = pos.reshape(res + 1, 8, 3)
    radii = np.linalg.norm(rings - rings.mean(axis=1, keepdims=True), axis=2)
    assert np.allclose(radii[0], 0.05, rtol=1e-4) and np.allclose(radii[-1], 0.10, rtol=1e-4)
    assert "UVMap" in me.uv_layers
    bpy.data.curves.remove(ob.data)


def test_cyclic_curve_and_round_caps(clean_scene, bpy_module):
    bpy = bpy_module
    bpy.ops.curve.primitive_bezier_circle_add()
    ob = bpy.context.active_object
    out = run_tubes(bpy, ob, radius=0.1, sides=12, caps="ROUND")
    _, use = mesh_arrays(out.data)
    assert np.all(use == 2) and not out.data.validate(verbose=False)
    assert len(out.data.vertices) == 4 * ob.data.resolution_u * 12  # a closed loop gets no caps
    bpy.data.curves.remove(ob.data)


def test_hair_curves_use_their_radius_attribute(clean_scene, bpy_module):
    bpy = bpy_module
    hair = bpy.data.hair_curves.new("Strands")
    hair.add_curves([5, 7])
    pts = np.concatenate((np.c_[np.zeros(5), np.zeros(5), np.arange(5.0)],
                          np.c_[np.ones(7), np.zeros(7), np.arange(7.0)])).astype(np.float32)
    hair.attributes["position"].data.foreach_set("vector", pts.ravel())
    radius = hair.attributes.get("radius") or hair.attributes.new("radius", "FLOAT", "POINT")
    radius.data.foreach_set("value", np.full(12, 0.02, np.float32))
    ob = bpy.data.objects.new("Strands", hair)
    bpy.context.scene.collection.objects.link(ob)
    out = run_tubes(bpy, ob, sides=6, caps="NONE")
    pos, use = mesh_arrays(out.data)
    assert len(pos) == 12 * 6
    assert np.allclose(np.linalg.norm(pos[:6, :2] - 0, axis=1), 0.02, atol=1e-6)
    bpy.data.objects.remove(ob)
    bpy.data.hair_curves.remove(hair)


def test_wire_mesh_edges_with_an_attribute_radius(clean_scene, bpy_module):
    bpy = bpy_module
    me = bpy.data.meshes.new("Streamlines")
    verts = [(0, 0, 0), (1, 0, 0), (2, 0.5, 0), (0, 3, 0), (0, 4, 1)]
    me.from_pydata(verts, [(1, 2), (0, 1), (3, 4)], [])
    attr = me.attributes.new("thickness", "FLOAT", "POINT")
    attr.data.foreach_set("value", np.array([1, 2, 3, 4, 5], np.float32))
    ob = bpy.data.objects.new("Streamlines", me)
    bpy.context.scene.collection.objects.link(ob)
    out = run_tubes(bpy, ob, radius_source="ATTRIBUTE", attribute="thickness", radius=0.01, sides=4, caps="FLAT")
    pos, use = mesh_arrays(out.data)
    assert len(pos) == 5 * 4 and np.all(use == 2)
    rings = pos.reshape(5, 4, 3)
    radii = np.sort(np.linalg.norm(rings - rings.mean(axis=1, keepdims=True), axis=2)[:, 0])
    assert np.allclose(radii, [0.01, 0.02, 0.03, 0.04, 0.05], atol=1e-6)


def test_a_missing_attribute_fails_and_leaves_the_scene_unchanged(clean_scene, bpy_module):
    bpy = bpy_module
    bpy.ops.mesh.primitive_circle_add()
    ob = bpy.context.active_object
    before = sorted(o.name for o in bpy.data.objects), sorted(m.name for m in bpy.data.meshes)
    with pytest.raises(RuntimeError, match="no float point attribute named 'nope'"):
        bpy.ops.tessera.tubes(radius_source="ATTRIBUTE", attribute="nope")
    assert (sorted(o.name for o in bpy.data.objects), sorted(m.name for m in bpy.data.meshes)) == before
    assert bpy.context.active_object == ob


def test_poll_explains_itself(clean_scene, bpy_module):
    bpy = bpy_module
    with pytest.raises(RuntimeError, match="Select curves, hair curves or meshes"):
        bpy.ops.tessera.tubes()


def test_poly_bezier_and_nurbs_splines_in_one_curve(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    bridge = addon_module("addon.curve_bridge")
    cu = bpy.data.curves.new("Mixed", "CURVE")
    cu.dimensions = "3D"
    poly = cu.splines.new("POLY")
    poly.points.add(3)
    for i, p in enumerate(poly.points):
        p.co = (i, 0, 0, 1)
        p.radius = 1 + i
    nurbs = cu.splines.new("NURBS")
    nurbs.points.add(4)
    for i, p in enumerate(nurbs.points):
        p.co = (i, 2, (i % 2), 1)
    nurbs.use_cyclic_u = True
    bez = cu.splines.new("BEZIER")
    bez.bezier_points.add(1)
    bez.bezier_points[1].co = (0, 4, 3)
    ob = bpy.data.objects.new("Mixed", cu)
    bpy.context.scene.collection.objects.link(ob)
    lines, notes = bridge.read_curve_object(ob, 0.1)
    assert notes == [] and lines.n_curves == 3
    assert list(lines.cyclic) == [False, True, False]
    assert lines.counts[0] == 4 and np.allclose(lines.radius[:4], [0.1, 0.2, 0.3, 0.4])
    assert lines.counts[2] == cu.resolution_u + 1
    out = run_tubes(bpy, ob, radius=0.1, sides=6, caps="ROUND")
    _, use = mesh_arrays(out.data)
    assert np.all(use == 2) and not out.data.validate(verbose=False)
    bpy.data.objects.remove(ob)
    bpy.data.curves.remove(cu)


def test_curvature_sampling_puts_rings_where_the_curve_bends(clean_scene, bpy_module, addon_module):
    """Curve Sampling Curvature: each Bézier segment gets its eq. 4.5 count of rings (6 straight, up to 32 in a
    bend), the ring centres on the Bézier, the radius along each segment."""
    bpy = bpy_module
    bz = addon_module("kernels.common.curves.bezier_curves")
    data = bpy.data.curves.new("Bend", "CURVE")
    data.dimensions = "3D"
    s = data.splines.new("BEZIER")
    s.bezier_points.add(2)
    co = np.array([[0, 0, 0], [4, 0, 0], [4.2, 0.3, 0]], np.float32)
    hl = co - np.array([[1, 0, 0], [1, 0, 0], [0, -3, 0]], np.float32)
    hr = co + np.array([[1, 0, 0], [1, 0, 0], [0, -3, 0]], np.float32)
    for name, values in (("co", co), ("handle_left", hl), ("handle_right", hr)):
        s.bezier_points.foreach_set(name, values.ravel())
    s.bezier_points.foreach_set("radius", np.array([1, 1, 2], np.float32))
    ob = bpy.data.objects.new("Bend", data)
    bpy.context.scene.collection.objects.link(ob)
    out = run_tubes(bpy, ob, radius=0.05, sides=6, caps="NONE", curve_sampling="CURVATURE")
    control = bz.segment_controls(co, hl, hr, False)
    counts = bz.curvature_counts(control)
    assert counts[0] == 6 and counts[1] == 32
    pos, _ = mesh_arrays(out.data)
    rings = pos.reshape(-1, 6, 3)
    want = bz.sample(control, counts, False)
    assert len(rings) == counts.sum() + 1
    assert np.allclose(rings.mean(axis=1), want.points, atol=1e-5)
    radii = np.linalg.norm(rings - rings.mean(axis=1, keepdims=True), axis=2).mean(axis=1)
    assert np.allclose(radii[[0, 6, -1]], [0.05, 0.05, 0.10], rtol=1e-3)

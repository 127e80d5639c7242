"""``tessera.surface_tessellate`` on the surfaces Blender itself makes (tier: blender): every Add › Surface primitive,
re-ordered to orders 2-6 and given random weights, becomes a mesh whose every vertex lies on the surface (checked with
an independent NURBS evaluator, geomdl, at the vertex's UV), whose triangles stay within the tolerance (measured on a
dense lattice in each triangle), welded (closed where the surface closes; open only on the surface's own border), and
Blender's own conversion lies on the same surface (its knots are the kernel's). Bad splines are refused, nothing
made."""

import numpy as np
import pytest
from geomdl import NURBS

pytestmark = pytest.mark.blender

PRIMITIVES = ("curve", "circle", "surface", "cylinder", "sphere", "torus")


def add_primitive(bpy, name):
    getattr(bpy.ops.surface, f"primitive_nurbs_surface_{name}_add")()
    return bpy.context.active_object


def read_mesh(me):
    pos = np.empty(len(me.vertices) * 3, np.float32)
    me.vertices.foreach_get("co", pos)
    verts = np.empty(len(me.loops), np.int32)
    me.loops.foreach_get("vertex_index", verts)
    edges = np.empty(len(me.loops), np.int32)
    me.loops.foreach_get("edge_index", edges)
    uv = np.empty(len(me.loops) * 2, np.float32)
    if len(me.loops):
        me.uv_layers["UVMap"].data.foreach_get("uv", uv)
    ev = np.empty(len(me.edges) * 2, np.int32)
    me.edges.foreach_get("vertices", ev)
    return pos.reshape(-1, 3).astype(np.float64), verts.reshape(-1, 3), edges, uv.reshape(-1, 3, 2), ev.reshape(-1, 2)


def reference(nurbs, spline):
    """geomdl's surface of a `SurfaceSpline` (its knots and wrapped points) and the spline's domain."""
    co, u, v = spline.points, spline.u, spline.v
    wrapped = nurbs.wrap_cyclic(nurbs.wrap_cyclic(co, u.order, u.cyclic, axis=1), v.order, v.cyclic, axis=0)
    ku, kv = nurbs.direction_knots(co.shape[1], u), nurbs.direction_knots(co.shape[0], v)
    ref = NURBS.Surface()
    ref.degree_u, ref.degree_v = u.order - 1, v.order - 1
    ref.ctrlpts_size_u, ref.ctrlpts_size_v = wrapped.shape[1], wrapped.shape[0]
    ref.ctrlptsw = nurbs.homogeneous(wrapped).transpose(1, 0, 2).reshape(-1, 4).tolist()
    ref.knotvector_u, ref.knotvector_v = ku.tolist(), kv.tolist()
    dom_u = (ku[u.order - 1], ku[wrapped.shape[1]])
    dom_v = (kv[v.order - 1], kv[wrapped.shape[0]])
    return ref, ku, kv, dom_u, dom_v, (u, v, co)


def on_reference(ref, ku, kv, dom_u, dom_v, uv):
    """geomdl's points (N, 3) at spline UVs in [0, 1] (N, 2), a hair inside the domain (it cannot take every end)."""
    f = np.clip(uv.astype(np.float64), 1e-9, 1 - 1e-9)
    x = dom_u[0] + f[:, 0] * (dom_u[1] - dom_u[0])
    y = dom_v[0] + f[:, 1] * (dom_v[1] - dom_v[0])
    params = np.stack([(x - ku[0]) / (ku[-1] - ku[0]), (y - kv[0]) / (kv[-1] - kv[0])], 1)
    return np.array(ref.evaluate_list([tuple(p) for p in params.tolist()]))


def variants(ob, rng):
    """The primitive as Blender makes it, then with every order from 2 to 6 its points allow and random weights."""
    yield "as made"
    s = ob.data.splines[0]
    for order in range(2, 7):
        s.order_u = min(order, s.point_count_u)
        if s.point_count_v > 1:
            s.order_v = min(order + 1 if order < 6 else 2, s.point_count_v)
        s.use_bezier_u = s.use_bezier_v = False  # Bézier knots need counts an order may not divide
        weights = rng.uniform(0.5, 2.0, len(s.points))
        co = np.array([p.co[:] for p in s.points], np.float64)
        co[:, 3] = weights
        s.points.foreach_set("co", co.astype(np.float32).ravel())
        yield f"order {s.order_u} x {s.order_v}, random weights"


@pytest.mark.parametrize("name", PRIMITIVES)
def test_every_surface_primitive_at_every_order_and_weight(clean_scene, bpy_module, addon_module, name):
    bpy = bpy_module
    nurbs = addon_module("kernels.common.curves.nurbs")
    bp = addon_module("kernels.surfaces.bezier_patches")
    curve_bridge = addon_module("addon.curve_bridge")
    rng = np.random.default_rng(len(name))
    source = add_primitive(bpy, name)
    unmet, variants_done = 0, 0
    for label in variants(source, rng):
        bpy.context.view_layer.objects.active = source
        tol = 5e-3
        assert bpy.ops.tessera.surface_tessellate(metrics={"TOLERANCE"}, tolerance=tol, max_level=64) == {"FINISHED"}
        out = bpy.context.active_object
        assert out is not source and out.type == "MESH"
        pos, tris, corner_edges, uv, edge_verts = read_mesh(out.data)
        spline = source.data.splines[0]
        size = np.abs(pos).max()
        if spline.point_count_v == 1:  # a curve in a surface object: a polyline of loose edges on the curve
            assert len(tris) == 0 and len(edge_verts) == len(pos) - (0 if spline.use_cyclic_u else 1)
            pieces, _ = nurbs.curve_pieces(co_of(spline), nurbs.Direction(
                spline.order_u, nurbs.knot_mode(spline.use_endpoint_u, spline.use_bezier_u), spline.use_cyclic_u))
            assert distance_to_curve(pieces, pos).max() < 1e-6 * size, label  # on the curve
            dense = dense_curve(pieces, 4000)
            a, b = pos[edge_verts[:, 0]], pos[edge_verts[:, 1]]  # and the curve within the tolerance of the edges
            ab = b - a
            f = np.clip(np.einsum("nsc,sc->ns", dense[:, None] - a[None], ab) / (ab * ab).sum(1), 0, 1)
            gap = np.linalg.norm(dense[:, None] - (a[None] + f[..., None] * ab[None]), axis=2).min(1)
            assert gap.max() <= tol, label
            variants_done += 1
            continue
        [(_, read)], _ = curve_bridge.read_surface_splines(source.data)
        ref, ku, kv, dom_u, dom_v, (u, v, co) = reference(nurbs, read)
        # every vertex on the surface, at its UV, by an independent evaluator
        pick = rng.choice(3 * len(tris), min(3000, 3 * len(tris)), replace=False)  # geomdl is pure Python
        corner_pos = pos[tris].reshape(-1, 3)[pick]
        want = on_reference(ref, ku, kv, dom_u, dom_v, uv.reshape(-1, 2)[pick])
        assert np.abs(corner_pos - want).max() < 1e-5 * size, label
        # welded: no edge in more than two faces; border only where the surface has one
        uses = np.bincount(corner_edges, minlength=len(edge_verts))
        assert uses.max() == 2, label
        border = uses == 1
        if u.cyclic and (v.cyclic or name == "sphere"):
            assert not border.any(), label
        else:
            corner_uv = {}
            for vert, t in zip(tris.ravel(), uv.reshape(-1, 2), strict=True):
                corner_uv.setdefault(int(vert), []).append(t)
            on_edge = np.array([any(_on_border(t, u.cyclic, v.cyclic) for t in corner_uv[int(i)])
                                for i in edge_verts[border].ravel()])
            assert on_edge.all(), label
        # within the tolerance: a dense lattice in every triangle against the surface at the same UVs, except in
        # the patches the kernel names as over it at Max Level (the operator then warns)
        ps = nurbs.patches_of([nurbs.SurfaceSpline(co, u, v)])
        result = bp.tessellate_surface(ps.patches, bp.PatchLod(metrics=("TOLERANCE",), tolerance=tol, max_level=64))
        assert len(result.mesh.triangles) == len(tris), label
        dev, patch = lattice_deviation(bp, ps, pos, tris, uv)
        assert dev[~np.isin(patch, result.parent[result.unmet])].max() <= tol, label
        at_max = (result.inner_levels[result.unmet] == 64).any(axis=1) | (
            result.edge_levels[result.edges.edge[result.unmet]] == 64).any(axis=1)
        assert at_max.all(), label
        unmet += len(result.unmet)
        variants_done += 1
    assert variants_done >= 2 and unmet <= 2 * variants_done


def _on_border(t, cyclic_u, cyclic_v):
    return ((not cyclic_u and (t[0] <= 1e-6 or t[0] >= 1 - 1e-6))
            or (not cyclic_v and (t[1] <= 1e-6 or t[1] >= 1 - 1e-6)))


def co_of(spline):
    return np.array([p.co[:] for p in spline.points], np.float32).astype(np.float64)


def piece_points(pieces, t):
    """Points (S, n, 3) of rational pieces (S, k, 4) at t (n,) or (S, n)."""
    from math import comb
    k = pieces.shape[1]
    t = np.broadcast_to(np.asarray(t, np.float64), (len(pieces),) + np.shape(t)[-1:])
    b = np.stack([comb(k - 1, i) * t ** i * (1 - t) ** (k - 1 - i) for i in range(k)], -1)
    h = np.einsum("sti,sic->stc", b, pieces)
    return h[..., :3] / h[..., 3:]


def dense_curve(pieces, n=400):
    return piece_points(pieces, np.linspace(0.0, 1.0, n)).reshape(-1, 3)


def distance_to_curve(pieces, points):
    """Each point's distance (N,) to the curve: the nearest of 2,000 samples a piece, then a ternary search of the
    parameter around it."""
    n = 2000
    grid = piece_points(pieces, np.linspace(0, 1, n + 1))  # (S, n + 1, 3)
    d = np.linalg.norm(grid[None] - points[:, None, None], axis=-1)  # (N, S, n + 1)
    flat = d.reshape(len(points), -1).argmin(axis=1)
    s, i = np.divmod(flat, n + 1)
    lo, hi = np.maximum(i - 1, 0) / n, np.minimum(i + 1, n) / n
    for _ in range(60):
        a, b = lo + (hi - lo) / 3, hi - (hi - lo) / 3
        da = np.linalg.norm(piece_points(pieces[s], a[:, None])[:, 0] - points, axis=1)
        db = np.linalg.norm(piece_points(pieces[s], b[:, None])[:, 0] - points, axis=1)
        lo, hi = np.where(da > db, a, lo), np.where(da > db, hi, b)
    return np.linalg.norm(piece_points(pieces[s], lo[:, None])[:, 0] - points, axis=1)


def lattice_deviation(bp, patch_set, pos, tris, uv, steps=6):
    """The largest distance (T,) between each triangle and the surface at a barycentric lattice of ``steps`` (28
    points at 6), the surface taken at the same point of the triangle's UVs (spline parameters); and each triangle's
    patch (T,)."""
    a, b = np.meshgrid(np.arange(steps + 1), np.arange(steps + 1))
    keep = a + b <= steps
    bary = np.stack([a[keep], b[keep], steps - a[keep] - b[keep]], 1) / steps
    on_mesh = np.einsum("sc,tcd->tsd", bary, pos[tris])
    at = np.einsum("sc,tcd->tsd", bary, uv.astype(np.float64)).reshape(-1, 2)
    patch, _ = patch_set.locate(uv.astype(np.float64).mean(axis=1))  # the patch that holds the triangle's centre
    b0 = patch_set.box[patch]
    local = (at.reshape(len(tris), -1, 2) - b0[:, None, :, 0]) / (b0[:, None, :, 1] - b0[:, None, :, 0])
    s = bp.evaluate(patch_set.patches[patch], np.clip(local[..., 0], 0, 1), np.clip(local[..., 1], 0, 1))
    return np.linalg.norm(on_mesh - s, axis=-1).max(axis=1), patch


@pytest.mark.parametrize("name", ("surface", "cylinder", "sphere", "torus"))
def test_blenders_own_conversion_lies_on_the_same_surface(clean_scene, bpy_module, addon_module, name):
    """Blender evaluates its surfaces at resolution x points equal steps of each direction's domain: those points
    are the kernel's patches' points at the same parameters (so the knots are Blender's)."""
    bpy = bpy_module
    nurbs = addon_module("kernels.common.curves.nurbs")
    bp = addon_module("kernels.surfaces.bezier_patches")
    ob = add_primitive(bpy, name)
    s = ob.data.splines[0]
    s.use_bezier_u = False
    s.order_u = min(4, s.point_count_u)
    co = co_of(s)
    co[:, 3] = np.random.default_rng(1).uniform(0.5, 2.0, len(co))
    s.points.foreach_set("co", co.astype(np.float32).ravel())
    me = ob.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
    blender = np.array([v.co[:] for v in me.vertices], np.float64)
    ob.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh_clear()
    [(_, spline)], _ = addon_module("addon.curve_bridge").read_surface_splines(ob.data)
    u, v = spline.u, spline.v
    ps = nurbs.patches_of([spline])
    n_u, n_v = s.resolution_u * s.point_count_u, s.resolution_v * s.point_count_v
    fu = np.linspace(0, 1, n_u + u.cyclic)[:n_u]
    fv = np.linspace(0, 1, n_v + v.cyclic)[:n_v]
    uu, vv = (a.ravel() for a in np.meshgrid(fu, fv, indexing="ij"))  # v fastest, as Blender lists them
    patch, st = ps.locate(np.stack([uu, vv], 1))
    su, sv = st[:, 0], st[:, 1]
    mine = bp.evaluate(ps.patches[patch], su[:, None], sv[:, None])[:, 0]
    assert len(mine) == len(blender)
    assert np.abs(mine - blender).max() < 1e-5 * np.abs(blender).max()


@pytest.mark.parametrize("change, words", [
    (lambda s: s.points[1].co.__setitem__(3, 0.0), "weights of zero or less"),
    (lambda s: s.points[2].co.__setitem__(0, float("nan")), "Spline 0 of .SurfSphere. has a point at NaN"),
])
def test_bad_surface_splines_are_refused_and_nothing_is_made(clean_scene, bpy_module, change, words):
    bpy = bpy_module
    ob = add_primitive(bpy, "sphere")
    change(ob.data.splines[0])
    before = len(bpy.data.objects), len(bpy.data.meshes)
    with pytest.raises(RuntimeError, match=f"surface spline 0 .*{words}|{words}"):
        bpy.ops.tessera.surface_tessellate()
    assert (len(bpy.data.objects), len(bpy.data.meshes)) == before


CURVE_MODES = ("UNIFORM", "ENDPOINT", "BEZIER", "ENDPOINT_BEZIER")


@pytest.mark.parametrize("order", range(2, 7))
def test_blenders_curve_evaluation_lies_on_the_pieces(clean_scene, bpy_module, addon_module, order):
    """Blender evaluates a NURBS curve at resolution equal steps of each span of its domain: its points are the
    pieces' points at the same parameters, for every knot mode, cyclic or not, with weights."""
    bpy = bpy_module
    nurbs = addon_module("kernels.common.curves.nurbs")
    rng = np.random.default_rng(order)
    for mode in CURVE_MODES:
        for cyclic in (False, True):
            n = 9
            d = nurbs.Direction(order, mode, cyclic)
            while True:
                try:
                    nurbs.direction_knots(n, d)
                    break
                except Exception:
                    n += 1
            cu = bpy.data.curves.new("c", "CURVE")
            cu.dimensions = "3D"
            s = cu.splines.new("NURBS")
            s.points.add(n - 1)
            co = np.c_[rng.normal(size=(n, 3)), rng.uniform(0.5, 2.0, n)].astype(np.float32)
            s.points.foreach_set("co", co.ravel())
            s.order_u, s.use_cyclic_u, s.resolution_u = order, cyclic, 6
            s.use_endpoint_u, s.use_bezier_u = "ENDPOINT" in mode, "BEZIER" in mode
            ob = bpy.data.objects.new("c", cu)
            bpy.context.scene.collection.objects.link(ob)
            ev = ob.evaluated_get(bpy.context.evaluated_depsgraph_get())
            blender = np.array([v.co[:] for v in ev.to_mesh().vertices], np.float64)
            ev.to_mesh_clear()
            pieces, span = nurbs.curve_pieces(co.astype(np.float64), d)
            x = np.linspace(span[0, 0], span[-1, 1], len(blender) + cyclic)[:len(blender)]
            k = np.clip(np.searchsorted(span[:, 0], x, side="right") - 1, 0, len(span) - 1)
            t = (x - span[k, 0]) / (span[k, 1] - span[k, 0])
            mine = piece_points(pieces[k], t[:, None])[:, 0]
            assert np.abs(mine - blender).max() < 1e-5 * np.abs(blender).max(), (mode, cyclic)
            bpy.data.objects.remove(ob)
            bpy.data.curves.remove(cu)


@pytest.mark.parametrize("primitive", ("nurbs_circle", "nurbs_path", "bezier_circle"))
def test_curve_to_adaptive_polyline_meets_the_tolerance_on_nurbs(clean_scene, bpy_module, addon_module, primitive):
    bpy = bpy_module
    nurbs = addon_module("kernels.common.curves.nurbs")
    getattr(bpy.ops.curve, f"primitive_{primitive}_add")()
    source = bpy.context.active_object
    rng = np.random.default_rng(5)
    s = source.data.splines[0]
    for order in (0, 2, 3, 4, 5, 6):
        if order and s.type == "NURBS":
            s.order_u = min(order, len(s.points))
            s.use_bezier_u = False
            co = co_of(s)
            co[:, 3] = rng.uniform(0.5, 2.0, len(co))
            s.points.foreach_set("co", co.astype(np.float32).ravel())
            s.points.foreach_set("radius", rng.uniform(0.5, 2.0, len(co)).astype(np.float32))
        elif order:
            continue
        bpy.context.view_layer.objects.active = source
        tol = 1e-3
        assert bpy.ops.tessera.curve_adaptive(mode="TOLERANCE", tolerance=tol, max_segments=1024) == {"FINISHED"}
        out = bpy.context.active_object.data.splines[0]
        pts = np.array([p.co[:3] for p in out.points], np.float64)
        if s.type != "NURBS":
            continue
        d = nurbs.Direction(s.order_u, nurbs.knot_mode(s.use_endpoint_u, s.use_bezier_u), s.use_cyclic_u)
        radius = np.array([p.radius for p in s.points], np.float64)
        pieces, _ = nurbs.curve_pieces(co_of(s), d, np.c_[radius, np.zeros(len(radius))])
        size = np.abs(pts).max()
        assert distance_to_curve(pieces[..., :4], pts).max() < 1e-6 * size, order
        edges = np.stack([np.arange(len(pts) - 1), np.arange(1, len(pts))], 1)
        if out.use_cyclic_u:
            edges = np.concatenate([edges, [[len(pts) - 1, 0]]])
        dense = dense_curve(pieces[..., :4], 2000)
        a, b = pts[edges[:, 0]], pts[edges[:, 1]]
        ab = b - a
        gap = np.empty(len(dense))
        for i in range(0, len(dense), 2000):
            q = dense[i:i + 2000]
            f = np.clip(np.einsum("nsc,sc->ns", q[:, None] - a[None], ab) / (ab * ab).sum(1), 0, 1)
            gap[i:i + 2000] = np.linalg.norm(q[:, None] - (a[None] + f[..., None] * ab[None]), axis=2).min(1)
        assert gap.max() <= tol, order
        # radius follows the curve as Blender interpolates it (rational, with the weights)
        r_out = np.array([p.radius for p in out.points], np.float64)
        assert r_out.min() >= radius.min() - 1e-6 and r_out.max() <= radius.max() + 1e-6


def test_tubes_sample_nurbs_curves_by_curvature(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    bz = addon_module("kernels.common.curves.bezier_curves")
    nurbs = addon_module("kernels.common.curves.nurbs")
    bpy.ops.curve.primitive_nurbs_path_add()
    ob = bpy.context.active_object
    s = ob.data.splines[0]
    co = co_of(s)
    co[:, 1] = [0, 0, 0, 1.5, 0]  # straight, then a bend
    co[:, 3] = [1, 2, 0.5, 2, 1]
    s.points.foreach_set("co", co.astype(np.float32).ravel())
    s.order_u = 3  # three pieces
    assert bpy.ops.tessera.tubes(radius=0.05, sides=6, caps="NONE", curve_sampling="CURVATURE") == {"FINISHED"}
    me = bpy.context.active_object.data
    pos = np.array([v.co[:] for v in me.vertices], np.float64)
    rings = pos.reshape(-1, 6, 3).mean(axis=1)
    d = nurbs.Direction(s.order_u, nurbs.knot_mode(s.use_endpoint_u, s.use_bezier_u), s.use_cyclic_u)
    [want] = bz.adaptive_nurbs(co[:, :3], co[:, 3], d, np.ones(5), np.zeros(5), bz.CurveSampling(mode="CURVATURE"))
    assert len(rings) == len(want.points) and np.allclose(rings, want.points, atol=1e-5)
    assert want.counts.max() > want.counts.min()  # more rings where it bends


def test_the_tolerance_is_in_scene_units(clean_scene, bpy_module):
    """A surface scaled 10 times at a tolerance 10 times larger gets the same mesh, and the report's figures are in
    scene units."""
    bpy = bpy_module
    counts = []
    for scale, tol in ((1.0, 1e-3), (10.0, 1e-2)):
        ob = add_primitive(bpy, "sphere")
        ob.scale = (scale,) * 3
        bpy.context.view_layer.update()
        assert bpy.ops.tessera.surface_tessellate(metrics={"TOLERANCE"}, tolerance=tol, max_level=64) == {"FINISHED"}
        counts.append(len(bpy.context.active_object.data.polygons))
    assert counts[0] == counts[1]


def test_a_bad_spline_is_named_by_its_place_in_blenders_list(clean_scene, bpy_module):
    bpy = bpy_module
    ob = add_primitive(bpy, "curve")  # spline 0: a single row (a curve), spline 1: a surface with a bad weight
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.surface.primitive_nurbs_surface_surface_add()
    bpy.ops.object.mode_set(mode="OBJECT")
    assert len(ob.data.splines) == 2
    ob.data.splines[1].points[5].co[3] = -1.0
    bpy.context.view_layer.objects.active = ob
    before = len(bpy.data.objects), len(bpy.data.meshes)
    with pytest.raises(RuntimeError, match="surface spline 1 has weights of zero or less"):
        bpy.ops.tessera.surface_tessellate()
    assert (len(bpy.data.objects), len(bpy.data.meshes)) == before


def test_normals_and_uvs_come_from_the_surface(clean_scene, bpy_module):
    """On Blender's NURBS sphere (radius 1 at the origin) every corner's normal is its position's direction, poles
    included, and the UVs are the spline's parameters: U from pole to pole, V once around."""
    bpy = bpy_module
    add_primitive(bpy, "sphere")
    assert bpy.ops.tessera.surface_tessellate(metrics={"TOLERANCE"}, tolerance=1e-3) == {"FINISHED"}
    me = bpy.context.active_object.data
    pos, tris, _, uv, _ = read_mesh(me)
    normals = np.array([n.vector[:] for n in me.corner_normals], np.float64).reshape(-1, 3, 3)
    radial = pos[tris] / np.linalg.norm(pos[tris], axis=-1, keepdims=True)
    assert np.einsum("tci,tci->tc", normals, radial).min() > 0.9999
    faces = np.array([p.normal[:] for p in me.polygons], np.float64)  # the faces wind as Blender's own face: out
    assert (np.einsum("ti,ti->t", faces, radial.mean(axis=1)) > 0).all()
    assert uv.min() >= 0.0 and uv.max() <= 1.0
    assert np.isclose(uv[..., 0].min(), 0.0) and np.isclose(uv[..., 0].max(), 1.0)
    assert np.isclose(uv[..., 1].min(), 0.0) and np.isclose(uv[..., 1].max(), 1.0)
    # U runs from pole to pole (the sphere's axis is z): U and z agree in order
    z = pos[tris][..., 2].ravel()
    assert abs(np.corrcoef(uv[..., 0].ravel(), z)[0, 1]) > 0.95

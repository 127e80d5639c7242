"""The "Tessera Phong" and "Tessera PN Triangles" geometry-nodes groups against the numpy patches (tier: blender)
and closed meshes staying closed. The farm-safe test of every group is in tests/common/test_node_library.py."""

import numpy as np
import pytest

pytestmark = pytest.mark.blender


def locate(points, positions, triangles):
    """For each point on the mesh, its triangle and barycentric coordinates (brute force, small meshes)."""
    a, b, c = (positions[triangles[:, k]] for k in range(3))
    v0, v1 = b - a, c - a
    d00, d01, d11 = (v0 * v0).sum(1), (v0 * v1).sum(1), (v1 * v1).sum(1)
    den = d00 * d11 - d01 * d01
    out_t, out_b = [], []
    for p in points:
        v2 = p - a
        d20, d21 = (v2 * v0).sum(1), (v2 * v1).sum(1)
        v = (d11 * d20 - d01 * d21) / den
        w = (d00 * d21 - d01 * d20) / den
        u = 1 - v - w
        bary = np.stack([u, v, w], 1)
        gap = np.linalg.norm(p - (bary[:, :, None] * np.stack([a, b, c], 1)).sum(1), axis=1)
        gap += np.maximum(0, -bary.min(axis=1))
        t = int(np.argmin(gap))
        out_t.append(t)
        out_b.append(bary[t])
    return np.array(out_t), np.array(out_b)


def evaluated_positions(bpy, ob):
    me = ob.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
    pos = np.empty(len(me.vertices) * 3, np.float32)
    me.attributes["position"].data.foreach_get("vector", pos)
    return pos.reshape(-1, 3).astype(np.float64), me


def group_modifier(bpy, addon_module, ob, module, **inputs):
    ng = addon_module("addon.node_groups")
    spec = addon_module(f"addon.tessellation.{module}").SPEC
    mod = ob.modifiers.new(spec.name, "NODES")
    mod.node_group = ng.ensure_group(spec)
    ng.set_inputs(mod, inputs)
    return mod


@pytest.mark.parametrize("method", ["PHONG", "PN"])
@pytest.mark.parametrize("shape", ["ico", "suzanne"])
def test_every_vertex_lies_on_the_kernels_surface(clean_scene, bpy_module, addon_module, shape, method):
    bpy = bpy_module
    patches = addon_module("kernels.tessellation.patches")
    if shape == "ico":
        bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=2)
    else:
        bpy.ops.mesh.primitive_monkey_add()
        bpy.ops.object.modifier_add(type="TRIANGULATE")
        bpy.ops.object.modifier_apply(modifier=bpy.context.active_object.modifiers[0].name)
    ob = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    me = ob.data
    pos = np.array([v.co for v in me.vertices], np.float64)
    nor = np.array([v.normal for v in me.vertices], np.float64)
    tris = np.array([p.vertices[:] for p in me.polygons])
    module = "phong_nodes" if method == "PHONG" else "pn_nodes"
    for level, alpha in ((1, 0.75), (2, 1.0)):
        mod = group_modifier(bpy, addon_module, ob, module, Level=level, **{"Shape Factor": 0.0})
        flat, _ = evaluated_positions(bpy, ob)
        addon_module("addon.node_groups").set_inputs(mod, {"Shape Factor": alpha})
        curved, out = evaluated_positions(bpy, ob)
        t, bary = locate(flat, pos, tris)
        if method == "PHONG":
            ref = np.einsum("pk,pkc->pc", patches.quadratic_basis(bary), patches.phong_control(pos[tris], nor[tris],
                                                                                               alpha)[t])
        else:  # PN with a shape factor: the linear point moved a of the way to the PN point
            pn = np.einsum("pk,pkc->pc", patches.cubic_basis(bary), patches.pn_control(pos[tris], nor[tris])[t])
            ref = flat + alpha * (pn - flat)
        assert np.abs(curved - ref).max() <= 1e-5 * np.abs(pos).max()
        if shape == "ico":  # closed stays closed
            edges = np.empty(len(out.loops), np.int32)
            out.attributes[".corner_edge"].data.foreach_get("value", edges)
            assert np.all(np.bincount(edges, minlength=len(out.edges)) == 2)
        ob.modifiers.remove(mod)


def mesh_object(bpy, name, positions, triangles):
    me = bpy.data.meshes.new(name)
    me.from_pydata(positions.tolist(), [], triangles.tolist())
    me.update()
    ob = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def sharp_mesh(bpy, shape, seed=0):
    """Meshes an artist has: flat-shaded (every edge sharp), smooth with marked sharp edges, random closed meshes
    with random sharp edges and flat faces, and custom normals (where the Normal node reads them)."""
    from tessera.tools.generators import random_irregular_closed

    rng = np.random.default_rng(seed)
    if shape == "random":
        v, f = random_irregular_closed(seed)
        ob = mesh_object(bpy, "random", v * 1.7, f)
    else:
        bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=2, radius=1.3)
        ob = bpy.context.active_object
    me = ob.data
    me.shade_smooth()
    if shape == "flat_ico":
        me.shade_flat()
    elif shape in ("sharp_ico", "random"):
        sharp = rng.random(len(me.edges)) < 0.3
        me.attributes.new("sharp_edge", "BOOLEAN", "EDGE").data.foreach_set("value", sharp)
        if shape == "random":
            smooth = rng.random(len(me.polygons)) > 0.2
            me.polygons.foreach_set("use_smooth", smooth)
    elif shape == "custom":
        n = np.array([v.normal for v in me.vertices]) + rng.normal(0, 0.2, (len(me.vertices), 3))
        me.normals_split_custom_set_from_vertices((n / np.linalg.norm(n, axis=1, keepdims=True)).tolist())
    me.update()
    return ob


def face_corners(me):
    """(F, 3) vertex indices of a triangle mesh's faces."""
    verts = np.empty(len(me.loops), np.int32)
    me.attributes[".corner_vert"].data.foreach_get("value", verts)
    return verts.reshape(-1, 3)


def containing_triangle(points, positions, triangles):
    """For points strictly inside triangles of the mesh, the triangle that holds each: (P,) int."""
    a, b, c = (positions[triangles[:, k]] for k in range(3))
    out = np.empty(len(points), np.int64)
    for lo in range(0, len(points), 512):
        p = points[lo:lo + 512, None, :]
        n = np.cross(b - a, c - a)
        inside = np.stack([np.einsum("ptk,tk->pt", np.cross(y - x, p - x), n) for x, y in ((a, b), (b, c), (c, a))])
        plane = np.abs(np.einsum("ptk,tk->pt", p - a, n)) / np.linalg.norm(n, axis=1)
        out[lo:lo + 512] = np.argmin(plane + 1e3 * (inside.min(axis=0) < 0), axis=1)
    return out


def barycentric(points, corners):
    """(P, 3) points in (P, 3, 3) triangles -> (P, 3) barycentric coordinates (least squares in the plane)."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    v0, v1, v2 = b - a, c - a, points - a
    d00, d01, d11 = (v0 * v0).sum(1), (v0 * v1).sum(1), (v1 * v1).sum(1)
    d20, d21 = (v2 * v0).sum(1), (v2 * v1).sum(1)
    den = d00 * d11 - d01 * d01
    v = (d11 * d20 - d01 * d21) / den
    w = (d00 * d21 - d01 * d20) / den
    return np.stack([1 - v - w, v, w], 1)


@pytest.mark.parametrize("mode", ["WATERTIGHT", "SPLIT"])
@pytest.mark.parametrize("method", ["PHONG", "PN"])
@pytest.mark.parametrize("shape", ["flat_ico", "sharp_ico", "random", "custom"])
def test_sharp_edges_follow_the_kernels_policy(clean_scene, bpy_module, addon_module, shape, method, mode):
    """Every output corner lies on the numpy kernel's surface for the same sharp-edge policy
    (`kernels.tessellation.tessellate.surface_inputs`): its face is located in the coarse triangle that holds it,
    and the corner's barycentric coordinates there give the kernel's point, and (where geometry nodes write custom
    normals) the kernel's shading normal. Watertight keeps a closed mesh closed; Split opens it exactly where the
    corner normals differ."""
    bpy = bpy_module
    compat = addon_module("addon.compat")
    patches = addon_module("kernels.tessellation.patches")
    tess = addon_module("kernels.tessellation.tessellate")
    ob = sharp_mesh(bpy, shape)
    arrays, _ = addon_module("addon.bridge").read_mesh(ob.data)
    if shape == "custom" and not compat.NORMAL_NODE_CORNER_NORMALS:  # documented: custom normals are ignored there
        arrays.corner_normals = None
    alpha = 0.75 if method == "PHONG" else 1.0
    inputs = tess.surface_inputs(arrays, tess.uniform_levels(arrays, 1), method,
                                 tess.SurfaceOptions(alpha=alpha, normal_mode=mode))
    module = "phong_nodes" if method == "PHONG" else "pn_nodes"
    label = "Watertight" if mode == "WATERTIGHT" else "Split"
    mod = group_modifier(bpy, addon_module, ob, module, Level=2, **{"Shape Factor": 0.0, "Sharp Edges": label})
    flat, out = evaluated_positions(bpy, ob)
    faces = face_corners(out)
    addon_module("addon.node_groups").set_inputs(mod, {"Shape Factor": alpha})
    curved, out = evaluated_positions(bpy, ob)
    assert np.array_equal(face_corners(out), faces)

    coarse = arrays.positions.astype(np.float64)
    t = containing_triangle(flat[faces].mean(axis=1), coarse, arrays.triangles)
    tri = np.repeat(t, 3)
    bary = barycentric(flat[faces.ravel()], coarse[arrays.triangles[tri]])
    corners = inputs.positions[inputs.mesh.triangles[tri]]
    normals = inputs.vertex_normals[inputs.mesh.triangles[tri]]
    if method == "PHONG":
        ref = np.einsum("pk,pkc->pc", patches.quadratic_basis(bary), patches.phong_control(corners, normals, alpha))
    else:
        ref = np.einsum("pk,pkc->pc", patches.cubic_basis(bary), patches.pn_control(corners, normals))
    assert np.abs(curved[faces.ravel()] - ref).max() <= 1e-5 * np.abs(coarse).max()
    if compat.has_set_mesh_normal_node():  # the shading: the kernel's normal field at every corner
        shading = inputs.shading_normals()[tri]
        if method == "PHONG":
            want = np.einsum("pk,pkc->pc", bary, shading)
        else:
            want = np.einsum("pk,pkc->pc", patches.quadratic_basis(bary), patches.pn_normal_control(corners, shading))
        want /= np.linalg.norm(want, axis=1, keepdims=True)
        got = np.empty(len(out.loops) * 3, np.float32)
        out.corner_normals.foreach_get("vector", got)
        assert np.abs(got.reshape(-1, 3) - want).max() <= 1e-4 + compat.CUSTOM_NORMAL_STORAGE_ERROR

    edges = np.empty(len(out.loops), np.int32)
    out.attributes[".corner_edge"].data.foreach_get("value", edges)
    boundary = int((np.bincount(edges, minlength=len(out.edges)) == 1).sum())
    if mode == "WATERTIGHT" or inputs.opened_edges == 0:
        assert boundary == 0  # closed stays closed
    else:  # each opened coarse edge leaves two boundary edges, split into 2^level pieces each
        assert boundary == 2 * inputs.opened_edges * 4

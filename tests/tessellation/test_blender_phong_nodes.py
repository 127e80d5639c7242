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

"""``tessera.parametric_surface_add`` (tier: blender): the mesh Blender holds is the kernel's welded surface (the
same positions, triangles and UVs), closed where the surface closes, at the 3D cursor; bad parameters change
nothing."""

import dataclasses

import numpy as np
import pytest

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

"""The "Tessera Displace" geometry-nodes group's Height and Object maps against the numpy reference (tier: blender);
its Tangent maps are checked through the displacement operator in test_blender_displacement.py."""

import numpy as np
import pytest

pytestmark = pytest.mark.blender


def sphere_with_map(bpy, values):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=24, ring_count=12, radius=1.0)
    ob = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    h, w = values.shape[:2]
    image = bpy.data.images.new("Map", w, h, float_buffer=True)
    rgba = np.ones((h, w, 4), np.float32)
    rgba[..., :3] = values
    image.pixels.foreach_set(rgba.ravel())
    image.update()
    return ob, image


def reference(ob, values, mid, strength, ts):
    """Each vertex's first corner's UV, the map sampled there (Linear, Extend), minus mid, times strength."""
    me = ob.data
    corner_verts = np.array([loop.vertex_index for loop in me.loops])
    first = np.full(len(me.vertices), len(corner_verts))
    np.minimum.at(first, corner_verts, np.arange(len(corner_verts)))
    uv = np.array([d.uv for d in me.uv_layers.active.data])
    rest = np.array([v.co for v in me.vertices])
    normals = np.array([v.normal for v in me.vertices])
    return rest, normals, (ts.sample_linear(values, uv[first]) - mid) * strength


def evaluated(bpy, ob):
    dg = bpy.context.evaluated_depsgraph_get()
    me = ob.evaluated_get(dg).to_mesh()
    co = np.empty(len(me.vertices) * 3)
    me.vertices.foreach_get("co", co)
    ob.evaluated_get(dg).to_mesh_clear()
    return co.reshape(-1, 3)


@pytest.mark.parametrize("kind", ["Height", "Object"])
def test_height_and_object_maps_equal_the_numpy_reference(clean_scene, bpy_module, addon_module, kind):
    bpy = bpy_module
    ts = addon_module("kernels.displacement.tangent_space")
    ng = addon_module("addon.node_groups")
    nodes = addon_module("addon.displacement.nodes")
    values = np.random.default_rng(11).uniform(0.0, 1.0, (16, 16, 3)).astype(np.float32)
    ob, image = sphere_with_map(bpy, values)
    mod = ob.modifiers.new("Displace", "NODES")
    mod.node_group = nodes.node_group(kind)
    ng.set_inputs(mod, {"Map": kind, "Image": image, "UV Map": ob.data.uv_layers.active.name, "Mid-Level": 0.4,
                        "Strength": 0.3})
    rest, normals, offset = reference(ob, values, 0.4, 0.3, ts)
    expected = rest + (normals * offset.mean(axis=1, keepdims=True) if kind == "Height" else offset)
    got = evaluated(bpy, ob)
    assert np.abs(got - expected).max() < 2e-6
    assert np.abs(got - rest).max() > 0.05  # really displaced
    bpy.data.images.remove(image)


def test_height_map_equals_blenders_displace_modifier_at_texel_centres(clean_scene, bpy_module, addon_module):
    """Where every vertex samples a texel centre, the group and Blender's Displace modifier (its image texture,
    intensity along the normal) give the same surface."""
    bpy = bpy_module
    ng = addon_module("addon.node_groups")
    nodes = addon_module("addon.displacement.nodes")
    n = 16
    values = np.random.default_rng(4).uniform(0.0, 1.0, (n, n, 1)).repeat(3, axis=2).astype(np.float32)
    ob, image = sphere_with_map(bpy, values)
    uv = ob.data.uv_layers.active.data
    corner_verts = [loop.vertex_index for loop in ob.data.loops]
    rng = np.random.default_rng(5)
    texel = {v: rng.integers(0, n, 2) for v in set(corner_verts)}
    for d, v in zip(uv, corner_verts, strict=True):  # every corner of a vertex: the centre of one texel
        d.uv = ((texel[v][0] + 0.5) / n, (texel[v][1] + 0.5) / n)
    mod = ob.modifiers.new("Displace", "NODES")
    mod.node_group = nodes.node_group("Height")
    ng.set_inputs(mod, {"Map": "Height", "Image": image, "UV Map": uv.id_data.uv_layers.active.name,
                        "Mid-Level": 0.5, "Strength": 0.2})
    ours = evaluated(bpy, ob)
    mod.show_viewport = False
    displace = ob.modifiers.new("Builtin", "DISPLACE")
    displace.texture = bpy.data.textures.new("Map", "IMAGE")
    displace.texture.image = image
    displace.texture.extension = "EXTEND"
    displace.texture_coords, displace.direction = "UV", "NORMAL"
    displace.mid_level, displace.strength = 0.5, 0.2
    builtin = evaluated(bpy, ob)
    assert np.abs(ours - builtin).max() < 1e-5
    bpy.data.textures.remove(displace.texture)
    bpy.data.images.remove(image)

"""The "Tessera Terrain" geometry-nodes group against the terrain kernel (tier: blender): per tile side the same
level as `kernels.terrain.lod.select` (DISTANCE and UNIFORM, powers of two) for random cameras, heights equal to
`HeightMap.sample`, and a welded, crack-free mesh (only the map's outline is boundary, no T-junction)."""

import numpy as np
import pytest

pytestmark = pytest.mark.blender


def height_image(bpy, samples):
    """A float, non-colour Blender image holding ``samples`` (H, W) in its red channel (row 0 at the bottom)."""
    h, w = samples.shape
    image = bpy.data.images.new("Heights", w, h, float_buffer=True, is_data=True)
    pixels = np.zeros((h, w, 4), np.float32)
    pixels[..., 0] = samples
    pixels[..., 3] = 1.0
    image.pixels.foreach_set(pixels.ravel())
    image.update()
    return image


def rough_heights(rng, w, h):
    """Smooth random hills in [0, 1] plus a little noise: (h, w) float32."""
    y, x = np.mgrid[0:h, 0:w] / max(w, h)
    z = sum(rng.uniform(0.2, 1) * np.sin(rng.uniform(2, 9) * x + rng.uniform(0, 6)) *
            np.cos(rng.uniform(2, 9) * y + rng.uniform(0, 6)) for _ in range(4))
    z = z + 0.05 * rng.random((h, w))
    return ((z - z.min()) / (z.max() - z.min())).astype(np.float32)


def terrain_object(bpy, addon_module, image, **inputs):
    ng = addon_module("addon.node_groups")
    spec = addon_module("addon.terrain.nodes").SPEC
    me = bpy.data.meshes.new("Terrain")
    ob = bpy.data.objects.new("Terrain", me)
    bpy.context.scene.collection.objects.link(ob)
    mod = ob.modifiers.new(spec.name, "NODES")
    mod.node_group = ng.ensure_group(spec)
    ng.set_inputs(mod, {"Image": image, **inputs})
    return ob, mod


def evaluated(bpy, ob):
    me = ob.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
    pos = np.empty(len(me.vertices) * 3, np.float32)
    me.attributes["position"].data.foreach_get("vector", pos)
    verts = np.empty(len(me.loops), np.int32)
    me.attributes[".corner_vert"].data.foreach_get("value", verts)
    starts = np.empty(len(me.polygons), np.int32)
    me.polygons.foreach_get("loop_start", starts)
    edges = np.empty(len(me.loops), np.int32)
    me.attributes[".corner_edge"].data.foreach_get("value", edges)
    return pos.reshape(-1, 3).astype(np.float64), verts, starts, edges, me


def add_camera(bpy, eye, target):
    from mathutils import Vector

    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    bpy.context.scene.collection.objects.link(cam)
    cam.location = eye
    cam.rotation_euler = (Vector(target) - Vector(eye)).to_track_quat("-Z", "Y").to_euler()
    bpy.context.scene.camera = cam
    return cam


def kernel_selection(addon_module, hm, tile_size, mode, max_level, d_max, eye):
    analysis = addon_module("kernels.terrain.analysis")
    lod = addon_module("kernels.terrain.lod")
    camera = addon_module("kernels.common.camera")
    table = analysis.tile_table(hm, tile_size, backend="numpy")
    cam = camera.Camera(camera.look_at_view(eye, np.zeros(3)), camera.perspective(0.7, 1.0, 0.05, 1e5), 256, 256)
    settings = lod.TerrainLod(mode=mode, d_max=d_max, max_level=max_level, culling=False, levels="POW2")
    return table, lod.select(hm, table, cam, settings)


@pytest.mark.parametrize("case", range(4))
def test_levels_heights_and_welding_equal_the_kernel(clean_scene, bpy_module, addon_module, case):
    bpy = bpy_module
    rng = np.random.default_rng(case)
    w, h = (int(rng.integers(40, 130)) for _ in range(2))
    tile_size = int(rng.choice([8, 16, 32]))
    texel, scale = float(rng.uniform(0.5, 2.0)), float(rng.uniform(5, 40))
    mode = "UNIFORM" if case == 3 else "DISTANCE"
    max_level = int(rng.choice([4, 16, 64]))
    d_max = float(rng.uniform(5, 30))
    samples = rough_heights(rng, w, h)
    heightmap_io = addon_module("kernels.terrain.heightmap_io")
    hm = heightmap_io.from_array(samples, texel_size=texel, scale=scale)
    half = np.array([w, h]) * texel * 0.5
    eye = np.array([*rng.uniform(-half, half), scale + rng.uniform(2, 30)])
    add_camera(bpy, eye, (0.0, 0.0, 0.0))
    image = height_image(bpy, samples)
    ob, _ = terrain_object(bpy, addon_module, image, **{
        "Texel Size": texel, "Height Scale": scale, "Tile Size": tile_size, "Max Level": max_level,
        "Detail Distance": d_max, "Level Mode": mode.title()})
    pos, verts, starts, edges, me = evaluated(bpy, ob)
    table, sel = kernel_selection(addon_module, hm, tile_size, mode, max_level, d_max, eye)
    if mode == "DISTANCE":  # the camera sees near and far tiles: several levels to agree on
        assert len(np.unique(sel.h_edges)) > 1

    # heights: the kernel's bilinear sample at each vertex's texel coordinates
    tx = pos[:, 0] / texel + (w - 1) / 2
    ty = pos[:, 1] / texel + (h - 1) / 2
    assert np.abs(pos[:, 2] - hm.sample(tx, ty)).max() <= 1e-5 * scale

    # every tile side carries exactly the kernel's level: its points at x0 + m (x1 - x0) / L, m = 0..L
    analysis = addon_module("kernels.terrain.analysis")
    ntx, nty = table.counts
    xb = analysis.tile_bounds(np.arange(ntx), tile_size, w)
    yb = analysis.tile_bounds(np.arange(nty), tile_size, h)
    tol = 1e-3

    def on_line(coord, value, other, lo, hi):
        hit = (np.abs(coord - value) < tol) & (other > lo - tol) & (other < hi + tol)
        return np.sort(other[hit])

    for row in range(nty + 1):
        y = yb[0][row] if row < nty else yb[1][-1]
        for col in range(ntx):
            lo, hi = xb[0][col], xb[1][col]
            level = sel.h_edges[row, col]
            want = lo + np.arange(level + 1) * (hi - lo) / level
            got = on_line(ty, y, tx, lo, hi)
            assert len(got) == len(want) and np.allclose(got, want, atol=tol), (row, col, got, want)
    for row in range(nty):
        lo, hi = yb[0][row], yb[1][row]
        for col in range(ntx + 1):
            x = xb[0][col] if col < ntx else xb[1][-1]
            level = sel.v_edges[row, col]
            want = lo + np.arange(level + 1) * (hi - lo) / level
            assert np.allclose(on_line(tx, x, ty, lo, hi), want, atol=tol), (row, col)

    # welded and crack-free: each edge used by two faces, except those on the map's outline; faces face up
    uses = np.bincount(edges, minlength=len(me.edges))
    assert uses.max() == 2
    ev = np.empty(len(me.edges) * 2, np.int32)
    me.attributes[".edge_verts"].data.foreach_get("value", ev)
    ends = ev.reshape(-1, 2)
    outline = np.zeros(len(pos), bool)
    outline |= (np.abs(tx) < tol) | (np.abs(tx - (w - 1)) < tol) | (np.abs(ty) < tol) | (np.abs(ty - (h - 1)) < tol)
    boundary = uses == 1
    assert outline[ends[boundary]].all()
    assert boundary.sum() == sum(sel.h_edges[0]) + sum(sel.h_edges[-1]) + sum(sel.v_edges[:, 0]) + \
        sum(sel.v_edges[:, -1])
    sizes = np.diff(np.append(starts, len(verts)))
    for k in (3, 4):
        faces = verts[np.concatenate([starts[sizes == k] + c for c in range(k)])].reshape(k, -1).T
        p = np.c_[tx, ty][faces]
        a, b = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
        area = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
        assert (area > 1e-9).all()
    assert set(np.unique(sizes)) <= {3, 4}


def test_no_image_or_a_one_texel_map_gives_an_empty_mesh(clean_scene, bpy_module, addon_module):
    """Nothing to mesh is an empty result, not an error (the modifier stack stays usable)."""
    bpy = bpy_module
    ob, mod = terrain_object(bpy, addon_module, None)
    assert len(evaluated(bpy, ob)[0]) == 0
    addon_module("addon.node_groups").set_inputs(mod, {"Image": height_image(bpy, np.ones((1, 5), np.float32))})
    assert len(evaluated(bpy, ob)[0]) == 0

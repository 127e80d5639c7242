"""Bake Impostor (tier: blender): a box rendered by Cycles from a 3 x 3 octahedral set of views into atlases, on a
card facing the camera; rendered by Cycles from a view's direction, the card shows that view (its silhouette's area
is the atlas tile's), for two views whose silhouettes differ."""

import numpy as np
import pytest

pytestmark = pytest.mark.blender


def coverage(alpha):
    return float((alpha > 0.5).mean())


def render_alpha(bpy, path, size=48):
    import OpenImageIO as oiio

    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.samples, scene.cycles.device = 1, "CPU"
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = True
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGBA"
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    inp = oiio.ImageInput.open(str(path))
    px = np.asarray(inp.read_image(0, 0, 0, 4, "float")).reshape(size, size, 4)
    inp.close()
    return px[..., 3]


def baked_box(bpy, tile=32, camera=True):
    """A box long in x (its views differ) baked into a 3 x 3 impostor, with a scene camera (the card tracks it) or
    none: the box, the camera (or None) and the card."""
    bpy.ops.mesh.primitive_cube_add(size=1.0, scale=(2.2, 0.5, 0.5))
    box = bpy.context.active_object
    cam = None
    if camera:
        cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
        bpy.context.scene.collection.objects.link(cam)
        bpy.context.scene.camera = cam
    bpy.context.view_layer.objects.active = box
    assert bpy.ops.tessera.impostor_bake(grid=3, tile=tile, samples=1) == {"FINISHED"}
    return box, cam, bpy.context.active_object


def test_the_card_shows_the_view_of_its_direction(clean_scene, bpy_module, addon_module, tmp_path):
    bpy = bpy_module
    oc = addon_module("kernels.impostors.octahedral")
    bake = addon_module("addon.impostors.bake")
    box, cam, card = baked_box(bpy)
    assert card.name == "Cube impostor" and card.constraints[0].target == cam
    colour = bpy.data.images["Cube impostor colour"]
    assert tuple(colour.size) == (96, 96) and colour.packed_file is not None
    px = np.empty(96 * 96 * 4, np.float32)
    colour.pixels.foreach_get(px)
    alpha = px.reshape(96, 96, 4)[..., 3]
    tiles = {(i, j): coverage(alpha[j * 32:(j + 1) * 32, i * 32:(i + 1) * 32]) for i in range(3) for j in range(3)}
    assert all(c > 0.02 for c in tiles.values())
    (i1, j1), (i2, j2) = (1, 1), (2, 1)  # straight down z; and a view from +x, where the box is short
    assert abs(tiles[(i1, j1)] - tiles[(i2, j2)]) > 0.05
    # Dilation (4 texels by default): the empty texels next to a view's outline carry colour, the far ones none
    rgb = px.reshape(96, 96, 4)[..., :3]
    yy, xx = np.mgrid[:32, :32]
    for (i, j) in tiles:
        a, c = alpha[j * 32:(j + 1) * 32, i * 32:(i + 1) * 32], rgb[j * 32:(j + 1) * 32, i * 32:(i + 1) * 32]
        ys, xs = np.nonzero(a > 0)
        d = np.min(np.abs(yy[..., None] - ys) + np.abs(xx[..., None] - xs), axis=-1)
        assert np.all(c[(d >= 1) & (d <= 4)].sum(axis=-1) > 0) and np.all(c[d > 4] == 0), (i, j)
    box.hide_render = True
    dirs = oc.view_directions(3)
    size = float(np.linalg.norm(np.ptp(np.array([box.matrix_world @ __import__("mathutils").Vector(c)
                                                  for c in box.bound_box]), axis=0)))
    cam.data.type, cam.data.ortho_scale = "ORTHO", size
    for (i, j) in ((i1, j1), (i2, j2)):
        loc, fwd, up = bake.view_camera(dirs[j, i], np.zeros(3), size)
        cam.location = loc * 3
        cam.rotation_euler = __import__("mathutils").Vector(fwd).to_track_quat("-Z", "Y").to_euler()
        bpy.context.view_layer.update()
        seen = coverage(render_alpha(bpy, tmp_path / f"card_{i}_{j}.png"))
        assert seen == pytest.approx(tiles[(i, j)], abs=0.04), (i, j)


def test_blended_views_mix_the_two_views_around_a_direction(clean_scene, bpy_module, addon_module, tmp_path):
    """Between two views' directions the blended card mixes both (premultiplied, bilinear over the grid): where only
    one view covers, the card is about half transparent; the nearest-view card shows one view (hard alpha, apart
    from the render's anti-aliased outline)."""
    bpy = bpy_module
    oc = addon_module("kernels.impostors.octahedral")
    bake = addon_module("addon.impostors.bake")
    from mathutils import Vector

    box, cam, card = baked_box(bpy)
    box.hide_render = True
    uv = (np.array([1.5, 1.0]) + 0.5) / 3  # the octahedral point halfway between views (1, 1) and (2, 1)
    direction = oc.decode(uv[None, :])[0]
    size = float(np.linalg.norm(np.ptp(np.array([box.matrix_world @ Vector(c) for c in box.bound_box]), axis=0)))
    cam.data.type, cam.data.ortho_scale = "ORTHO", size
    loc, fwd, _ = bake.view_camera(direction, np.zeros(3), size)
    cam.location = loc * 3
    cam.rotation_euler = Vector(fwd).to_track_quat("-Z", "Y").to_euler()
    bpy.context.view_layer.update()

    def half_transparent(alpha):
        return float(((alpha > 0.3) & (alpha < 0.7)).mean())

    blended = half_transparent(render_alpha(bpy, tmp_path / "blended.png"))
    colour = next(n.image for n in card.active_material.node_tree.nodes if n.type == "TEX_IMAGE")
    card.data.materials[0] = bake.card_material("nearest", colour, 3, False, blend=False)
    nearest = half_transparent(render_alpha(bpy, tmp_path / "nearest.png"))
    assert blended > nearest + 0.03, (blended, nearest)


def read_glb(path):
    """The JSON and the binary chunk of a .glb file."""
    import json
    import struct

    data = open(path, "rb").read()
    assert data[:4] == b"glTF"
    length = struct.unpack("<I", data[12:16])[0]
    doc = json.loads(data[20:20 + length])
    binary = data[20 + length + 8:]
    return doc, binary


def test_the_card_exports_to_gltf_with_its_atlas_and_layout(clean_scene, bpy_module, addon_module, tmp_path):
    """Export Impostor (glTF): one node with the layout in its extras, an unlit alpha-blended material whose base
    colour is the whole colour atlas, the quad's UVs inside the front view's cell; the atlas image in the file has the
    baked alpha. A folder that does not exist is refused and nothing is written or left in the scene."""
    import OpenImageIO as oiio

    bpy = bpy_module
    oc = addon_module("kernels.impostors.octahedral")
    _, _, card = baked_box(bpy, tile=16, camera=False)
    objects, meshes, materials = set(bpy.data.objects), set(bpy.data.meshes), set(bpy.data.materials)
    path = tmp_path / "card.glb"
    assert bpy.ops.tessera.impostor_export(filepath=str(path)) == {"FINISHED"}
    assert set(bpy.data.objects) == objects and set(bpy.data.meshes) == meshes and set(bpy.data.materials) == materials
    assert bpy.context.active_object == card and card.select_get()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["card.glb"]  # no temporary file left
    doc, binary = read_glb(path)
    (node,) = doc["nodes"]
    extras = node["extras"]["tessera_impostor"]
    i, j = oc.cell_of(np.array([0.0, -1.0, 0.0]), 3)
    assert extras["grid"] == 3 and extras["layout"] == "octahedral" and extras["fallback_view"] == [i, j]
    (material,) = doc["materials"]
    assert "KHR_materials_unlit" in material.get("extensions", {}) and material.get("alphaMode") == "BLEND"
    texture = doc["textures"][material["pbrMetallicRoughness"]["baseColorTexture"]["index"]]
    image = doc["images"][texture["source"]]
    assert image["mimeType"] == "image/png"
    accessor = doc["accessors"][doc["meshes"][node["mesh"]]["primitives"][0]["attributes"]["TEXCOORD_0"]]
    assert accessor["componentType"] == 5126 and accessor["type"] == "VEC2"  # float pairs
    uv_view = doc["bufferViews"][accessor["bufferView"]]
    start = uv_view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
    uvs = np.frombuffer(binary, np.float32, 2 * accessor["count"], start).reshape(-1, 2)
    lo, hi = uvs.min(axis=0), uvs.max(axis=0)
    # glTF's v runs down the image: the cell (i, j) of an atlas with row 0 at the bottom is rows 2 - j from the top
    assert np.allclose(lo, [i / 3, (2 - j) / 3], atol=1e-6) and np.allclose(hi, [(i + 1) / 3, (3 - j) / 3], atol=1e-6)
    view = doc["bufferViews"][image["bufferView"]]
    png = tmp_path / "atlas.png"
    png.write_bytes(binary[view.get("byteOffset", 0):view.get("byteOffset", 0) + view["byteLength"]])
    inp = oiio.ImageInput.open(str(png))
    spec = inp.spec()
    pixels = np.asarray(inp.read_image(0, 0, 0, spec.nchannels, "float")).reshape(spec.height, spec.width, -1)
    inp.close()
    baked = np.empty(48 * 48 * 4, np.float32)
    next(n.image for n in card.active_material.node_tree.nodes if n.type == "TEX_IMAGE").pixels.foreach_get(baked)
    baked_alpha = baked.reshape(48, 48, 4)[::-1, :, 3]  # Blender's row 0 is the bottom, PNG's the top
    assert (spec.width, spec.height, spec.nchannels) == (48, 48, 4)
    assert np.array_equal(pixels[..., 3] > 0.5, baked_alpha > 0.5)
    png.unlink()
    with pytest.raises(RuntimeError, match="does not exist"):
        bpy.ops.tessera.impostor_export(filepath=str(tmp_path / "missing" / "card.glb"))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["card.glb"]
    assert set(bpy.data.objects) == objects and set(bpy.data.meshes) == meshes


def test_bake_impostor_makes_a_card_for_every_selected_object(clean_scene, bpy_module):
    """As Blender's own object operators: a card for each selected object with geometry (the active one first), the
    cards selected afterwards; a selected camera is left alone."""
    bpy = bpy_module
    bpy.ops.mesh.primitive_cube_add(size=1.0)
    cube = bpy.context.active_object
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(2, 0, 0))
    sphere = bpy.context.active_object
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    bpy.context.scene.collection.objects.link(cam)
    for ob in (cube, sphere, cam):
        ob.select_set(True)
    bpy.context.view_layer.objects.active = cube
    assert bpy.ops.tessera.impostor_bake(grid=2, tile=16, samples=1) == {"FINISHED"}
    cards = sorted(o.name for o in bpy.data.objects if o.name.endswith(" impostor"))
    assert cards == ["Cube impostor", "Sphere impostor"]
    selected = {o.name for o in bpy.context.selected_objects}
    assert set(cards) <= selected and not {"Cube", "Sphere"} & selected
    assert bpy.context.view_layer.objects.active.name in cards

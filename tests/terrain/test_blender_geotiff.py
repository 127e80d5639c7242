"""GeoTIFF terrains in Blender (tier: blender): true scale and placement, adjacent files side by side or as one
terrain, voids filled or cut, refusals that change nothing, settings that survive save and reload."""

import numpy as np
import pytest
from tessera.tools.geotiff_files import write_geotiff
from test_blender_terrain import add_camera, mesh_tris

pytestmark = pytest.mark.blender
NODATA = -32768


def _dem(h=97, w=129):
    y, x = np.mgrid[0:h, 0:w] / 64.0
    top = 800 + 300 * np.sin(3 * x) * np.cos(2 * y) + 40 * np.sin(17 * x * y)
    return np.round(top).astype(np.int16)


@pytest.fixture
def scene(clean_scene, bpy_module):
    """A clean scene without a geographic origin (the first georeferenced terrain sets one)."""
    bpy_module.context.scene.pop("tessera_geo_origin", None)
    return bpy_module


def _add(bpy, path, **kw):
    kw.setdefault("tile_size", 32)
    kw.setdefault("culling", False)
    kw.setdefault("mode", "UNIFORM")  # the full grid: every sample a vertex
    assert bpy.ops.tessera.terrain_add(filepath=path, **kw) == {"FINISHED"}
    return bpy.context.active_object


def test_a_geotiff_terrain_has_the_files_scale_heights_and_place(scene, tmp_path):
    bpy = scene
    top = _dem()
    west = write_geotiff(str(tmp_path / "west.tif"), top[:, :65], spacing=(10.0, 10.0), corner=(600000.0, 5200000.0),
                         nodata=NODATA)
    east = write_geotiff(str(tmp_path / "east.tif"), top[:, 64:], spacing=(10.0, 10.0),
                         corner=(600000.0 + 640.0, 5200000.0), nodata=NODATA)  # one column shared, as SRTM does
    add_camera(bpy, (0, -1500, 1500))
    a = _add(bpy, west, height_scale=100.0, texel_size=3.0)  # ignored: the file gives them
    assert tuple(a.location) == (0.0, 0.0, 0.0) and "tessera_geo_origin" in bpy.context.scene
    pos, tris = mesh_tris(a.data)
    assert len(pos) == 97 * 65 and np.ptp(pos[:, 0]) == 640.0 and np.ptp(pos[:, 1]) == 960.0
    assert np.array_equal(np.sort(pos[:, 2]), np.sort(top[:, :65].astype(np.float32).ravel()))  # true heights
    b = _add(bpy, east)
    assert tuple(b.location) == pytest.approx((640.0, 0.0, 0.0))  # beside the first, where its data lies
    world_a = {tuple(np.round(a.matrix_world @ v.co, 3)) for v in a.data.vertices}
    world_b = {tuple(np.round(b.matrix_world @ v.co, 3)) for v in b.data.vertices}
    assert len(world_a & world_b) == 97  # the shared column: the same points, so the two meshes meet
    # both picked at once: one terrain, the same points as the two
    assert bpy.ops.tessera.terrain_add(filepath=west, directory=str(tmp_path), tile_size=32, culling=False,
                                       mode="UNIFORM", files=[{"name": "west.tif"}, {"name": "east.tif"}]) == {
        "FINISHED"}
    c = bpy.context.active_object
    assert c.tessera.terrain.tile_files == "east.tif"
    world_c = {tuple(np.round(c.matrix_world @ v.co, 3)) for v in c.data.vertices}
    assert world_c == world_a | world_b


def test_voids_fill_or_cut_and_survive_save_and_reload(scene, tmp_path):
    bpy = scene
    top = _dem()
    top[30:50, 40:70] = NODATA
    path = write_geotiff(str(tmp_path / "lake.tif"), top, spacing=(5.0, 5.0), nodata=NODATA)
    add_camera(bpy, (0, -800, 800))
    filled = _add(bpy, path, voids="FILL")
    pos, _ = mesh_tris(filled.data)
    valid = top[top != NODATA]
    assert pos[:, 2].min() >= valid.min() and pos[:, 2].max() <= valid.max()  # no -32768 pit
    holes = _add(bpy, path, voids="HOLES")
    hpos, htris = mesh_tris(holes.data)
    assert len(htris) < len(mesh_tris(filled.data)[1]) and hpos[:, 2].min() >= valid.min()
    # no vertex inside the void (its samples are x 40..69, y 30..49 from the top; positions centred)
    x = hpos[:, 0] / 5.0 + 64.0
    y = 48.0 - hpos[:, 1] / 5.0
    assert not ((x > 40) & (x < 69) & (y > 30) & (y < 49)).any()
    n, name = len(htris), holes.name
    blend = str(tmp_path / "geo.blend")
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    bpy.ops.wm.open_mainfile(filepath=blend)
    ob = bpy.data.objects[name]
    assert ob.tessera.terrain.voids == "HOLES" and ob.tessera.terrain.georeferenced
    bpy.context.view_layer.objects.active = ob
    assert bpy.ops.tessera.terrain_bake() == {"FINISHED"}
    assert len(mesh_tris(ob.data)[1]) == n


def test_bad_geotiffs_are_refused_by_name_and_change_nothing(scene, tmp_path):
    bpy = scene
    top = _dem(40, 50)
    (tmp_path / "junk.asc").write_text("ncols 3\nnrows\n")
    empty = write_geotiff(str(tmp_path / "empty.tif"), np.full_like(top, NODATA), nodata=NODATA)
    n_objects, n_meshes = len(bpy.data.objects), len(bpy.data.meshes)
    for path, words in ((str(tmp_path / "junk.asc"), "junk.asc"), (empty, "empty.tif.*no-data")):
        with pytest.raises(RuntimeError, match=words):
            bpy.ops.tessera.terrain_add(filepath=path)
    with pytest.raises(RuntimeError, match="No such elevation file"):
        bpy.ops.tessera.terrain_add(filepath=write_geotiff(str(tmp_path / "ok.tif"), top), tile_files="missing.tif")
    assert len(bpy.data.objects) == n_objects and len(bpy.data.meshes) == n_meshes
    assert "tessera_geo_origin" not in bpy.context.scene


def test_elevation_files_that_are_not_geotiff_and_a_picture_band(scene, tmp_path):
    """An ESRI ASCII grid with voids cut out and an ERDAS Imagine file become terrains at their true scale; a
    picture (RGB bytes) is refused by name until its Band is chosen."""
    pytest.importorskip("rasterio")
    from tessera.tools.geotiff_files import write_raster

    bpy = scene
    top = _dem(41, 49).astype(np.float32)  # 48 x 40 texels: whole tiles of 8 (Uniform is then every sample)
    void = np.zeros(top.shape, bool)
    void[10:15, 20:30] = True
    asc = write_raster(str(tmp_path / "dem.asc"), np.where(void, -9999.0, top).astype(np.float32), nodata=-9999.0,
                       driver="AAIGrid", spacing=(5.0, 5.0), corner=(0.0, 200.0))
    add_camera(bpy, (0, -300, 300))
    ob = _add(bpy, asc, voids="HOLES", tile_size=8)
    pos, tris = mesh_tris(ob.data)
    assert np.ptp(pos[:, 0]) == 240.0 and np.ptp(pos[:, 1]) == 200.0
    assert set(np.round(pos[:, 2], 3)) <= set(np.round(top[~void], 3))  # every vertex a written height
    assert len(pos) == top.size - void.sum()  # the void's samples cut out
    img = write_raster(str(tmp_path / "dem.img"), top, driver="HFA", spacing=(2.0, 2.0))
    pos, _ = mesh_tris(_add(bpy, img, tile_size=8).data)
    assert np.ptp(pos[:, 0]) == 96.0 and np.array_equal(np.sort(pos[:, 2]), np.sort(top.ravel()))
    rgb = np.stack([np.clip(top / 4, 0, 255).astype(np.uint8)] * 3)
    photo = write_raster(str(tmp_path / "photo.tif"), rgb, PHOTOMETRIC="RGB")
    n_objects = len(bpy.data.objects)
    with pytest.raises(RuntimeError, match=r"photo\.tif is a picture.*Band"):
        bpy.ops.tessera.terrain_add(filepath=photo)
    assert len(bpy.data.objects) == n_objects
    ob = _add(bpy, photo, band=2, tile_size=8)
    assert ob.tessera.terrain.band == 2 and len(ob.data.vertices) == top.size

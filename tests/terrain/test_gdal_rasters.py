"""Elevation rasters as GDAL writes them (the files QGIS, gdal_translate and DEM downloads give users), read through
the bundled GDAL: every height equal to the height written (after scale, offset and units), the extent right, voids
never a height, and what cannot be read refused with the file's name and GDAL's reason. The files are written here
with GDAL from heights the test knows; the terrain is compared with those heights, not with a second reading."""

import numpy as np
import pytest

rasterio = pytest.importorskip("rasterio")

from rasterio.transform import Affine  # noqa: E402
from tessera.kernels.common.errors import InvalidInputError  # noqa: E402
from tessera.kernels.terrain import analysis as ta  # noqa: E402
from tessera.kernels.terrain import gdal_raster  # noqa: E402
from tessera.kernels.terrain import geotiff as gt  # noqa: E402
from tessera.tools.geotiff_files import write_raster  # noqa: E402

from tools.ridged_terrain import ridged_terrain  # noqa: E402

US_FOOT = 1200.0 / 3937.0


def _heights(h=120, w=150, seed=3):
    """Metres, top row first: float64 (the truth every file is written from)."""
    return ridged_terrain(max(h, w), seed=seed, octaves=5)[:h, :w].astype(np.float64) * 900.0 + 250.0


def _voids(h, w):
    void = np.zeros((h, w), bool)
    void[h // 4:h // 4 + h // 8, w // 3:w // 3 + w // 5] = True  # a lake
    void[0:2, 2 * w // 3:2 * w // 3 + w // 8] = True  # on the northern edge
    void[2 * h // 3, w // 16] = True  # one bad sample
    return void


def _read(path, reader="gdal", **kw):
    hm, geo = gt.read_geotiff([str(path)], **kw)
    assert geo.files[0].reader == reader
    return hm, geo


def _valid_exact(hm, expected_top, void=None):
    """The terrain's heights (bottom row first) equal the expected ones where valid; voids inside the valid range."""
    got = hm.heights()[::-1]  # top first, as written
    want = expected_top.astype(np.float32) if hm.scale == 1.0 else expected_top
    void = np.zeros(expected_top.shape, bool) if void is None else void
    assert np.isfinite(got).all()
    np.testing.assert_allclose(got[~void], want[~void], rtol=0, atol=abs(float(np.max(want))) * 2e-7)
    if void.any():
        assert got[void].min() >= want[~void].min() - 1e-3 and got[void].max() <= want[~void].max() + 1e-3


def test_the_lowest_float32_as_no_data_is_a_void_never_a_height(tmp_path, elevation_reader):
    top = _heights()
    void = _voids(*top.shape)
    lowest = float(np.finfo(np.float32).min)
    data = np.where(void, lowest, top).astype(np.float32)
    data[5, 5] = 0.0  # a real sample at sea level stays a height
    top = top.copy()
    top[5, 5] = 0.0
    path = write_raster(str(tmp_path / "low.tif"), data, nodata=lowest, TILED=True, COMPRESS="DEFLATE")
    hm, _ = _read(path, elevation_reader)
    assert hm.samples.void_count == void.sum()
    _valid_exact(hm, top, void)


def test_scale_and_offset_are_applied(tmp_path, elevation_reader):
    top = _heights()
    stored = np.round((top - 1000.0) / 0.1).astype(np.int16)  # int16 decimetres about 1000 m
    hm, geo = _read(write_raster(str(tmp_path / "dm.tif"), stored, scale=0.1, offset=1000.0), elevation_reader)
    _valid_exact(hm, stored.astype(np.float64) * 0.1 + 1000.0)
    assert geo.files[0].quantum == pytest.approx(0.1) and "x 0.1 + 1000" in " ".join(geo.files[0].notes)


def test_us_survey_feet_named_only_by_epsg_codes(tmp_path):
    """EPSG:2227+6360 (California zone 3, NAVD88 height, both in US survey feet): GDAL writes the two codes and no
    unit keys; texels and heights come out in metres."""
    top_ft = _heights() / US_FOOT
    path = write_raster(str(tmp_path / "ft.tif"), top_ft.astype(np.float32), crs="EPSG:2227+6360",
                        spacing=(10.0, 10.0), corner=(6000000.0, 2000000.0))
    hm, geo = _read(path)
    assert hm.texel == pytest.approx((10 * US_FOOT, 10 * US_FOOT), rel=1e-9)
    assert geo.vertical == pytest.approx(US_FOOT, rel=1e-9)
    np.testing.assert_allclose(hm.heights()[::-1], top_ft.astype(np.float32) * US_FOOT, rtol=1e-6)


@pytest.mark.parametrize("internal", [True, False], ids=["internal", "msk-file"])
def test_a_mask_band_marks_voids(tmp_path, internal):
    top = _heights()
    void = _voids(*top.shape)
    data = np.where(void, 0, top).astype(np.float32)  # zeros under the mask: a pit if the mask were ignored
    path = write_raster(str(tmp_path / "mask.tif"), data, mask=~void, internal_mask=internal, TILED=True,
                        COMPRESS="LZW")
    assert (tmp_path / "mask.tif.msk").exists() != internal
    hm, _ = _read(path)
    assert hm.samples.void_count == void.sum()
    _valid_exact(hm, top, void)
    holes, _ = _read(str(tmp_path / "mask.tif"), voids="HOLES")
    assert holes.samples.cut and holes.samples.void_count == void.sum()


@pytest.mark.parametrize("options", [
    dict(COMPRESS="ZSTD", PREDICTOR=3, TILED=True),
    dict(COMPRESS="LERC", MAX_Z_ERROR=0, TILED=True),
    dict(COMPRESS="DEFLATE", PREDICTOR=2, ZLEVEL=9),
    dict(COMPRESS="LZW", BIGTIFF="YES", TILED=True, BLOCKXSIZE=32, BLOCKYSIZE=32),
    dict(COMPRESS="PACKBITS", INTERLEAVE="BAND"),
], ids=["zstd", "lerc", "deflate-strips", "bigtiff", "packbits"])
def test_every_compression_gdal_writes_reads_exactly(tmp_path, options):
    top = _heights()
    dtype = np.int16 if options.get("PREDICTOR") == 2 or options["COMPRESS"] == "PACKBITS" else np.float32
    data = top.astype(dtype)
    hm, geo = _read(write_raster(str(tmp_path / "c.tif"), data, **options))
    _valid_exact(hm, data.astype(np.float64))
    assert geo.origin == (500015.0, 4599985.0) and geo.spacing == (30.0, 30.0)


def test_a_sparse_file_reads_its_empty_blocks_as_voids(tmp_path):
    """SPARSE_OK: blocks never written are not in the file; GDAL gives them the no-data value."""
    path = str(tmp_path / "sparse.tif")
    top = _heights(128, 128).astype(np.float32)
    profile = dict(driver="GTiff", width=128, height=128, count=1, dtype="float32", crs="EPSG:32633",
                   transform=Affine(30.0, 0, 500000.0, 0, -30.0, 4600000.0), nodata=-9999.0, tiled=True,
                   blockxsize=64, blockysize=64, SPARSE_OK=True)
    with rasterio.open(path, "w", **profile) as ds:
        from rasterio.windows import Window

        for r, c in ((0, 0), (64, 64), (0, 64)):  # the bottom-left block is never written
            ds.write(top[r:r + 64, c:c + 64][None], window=Window(c, r, 64, 64))
    hm, _ = _read(path)
    void = np.zeros(top.shape, bool)
    void[64:, :64] = True
    assert hm.samples.void_count == void.sum()
    _valid_exact(hm, top.astype(np.float64), void)


def test_a_cloud_optimised_geotiff_with_overviews(tmp_path):
    top = _heights(300, 260).astype(np.float32)
    path = write_raster(str(tmp_path / "cog.tif"), top, driver="COG", COMPRESS="DEFLATE", OVERVIEWS="AUTO",
                        BLOCKSIZE=128)
    with rasterio.open(path) as ds:
        assert ds.overviews(1)  # the file really has overviews; the terrain reads the full resolution
    hm, geo = _read(path)
    _valid_exact(hm, top.astype(np.float64))
    assert (hm.width, hm.height) == (260, 300)


def test_pixel_is_point_and_geographic_placement(tmp_path):
    top = _heights(60, 80).astype(np.float32)
    _, geo = _read(write_raster(str(tmp_path / "pt.tif"), top, point=True, corner=(1000.0, 2000.0),
                                spacing=(3.0, 3.0)))
    assert geo.origin == pytest.approx((1000.0, 2000.0), abs=1e-9)  # the first sample sits on the corner given
    arc = 1 / 3600
    hm, geo = _read(write_raster(str(tmp_path / "geo.tif"), top, crs="EPSG:4326", spacing=(arc, arc),
                                 corner=(7.0 - 0.5 * arc, 46.5 + 30 * arc - 0.5 * arc + arc)))
    tx, ty = hm.texel
    assert geo.files[0].geographic and tx == pytest.approx(21.3, abs=0.05) and ty == pytest.approx(30.87, abs=0.02)
    assert geo.centre[1] == pytest.approx(46.5 + arc / 2, abs=1e-9)


def test_srtm_hgt_ascii_grid_and_erdas_imagine(tmp_path):
    """Formats that are not GeoTIFF: an SRTM tile (1201 x 1201, named for its corner), an ESRI ASCII grid with its
    no-data value, an ERDAS Imagine file."""
    top = np.round(_heights(1201, 1201, seed=5)).astype(np.int16)
    hgt = write_raster(str(tmp_path / "N46E007.hgt"), top, crs="EPSG:4326", spacing=(1 / 1200, 1 / 1200),
                       corner=(7.0 - 0.5 / 1200, 47.0 + 0.5 / 1200), driver="SRTMHGT")
    hm, geo = _read(hgt)
    _valid_exact(hm, top.astype(np.float64))
    assert geo.origin == pytest.approx((7.0, 47.0), abs=1e-9) and geo.files[0].geographic
    assert hm.texel[1] == pytest.approx(92.6, abs=0.1)  # 3 arc-seconds north-south
    small = _heights(50, 70)
    void = _voids(50, 70)
    asc = write_raster(str(tmp_path / "dem.asc"), np.where(void, -9999.0, np.round(small, 2)).astype(np.float32),
                       nodata=-9999.0, driver="AAIGrid", spacing=(5.0, 5.0), corner=(0.0, 250.0))
    hm, geo = _read(asc)
    assert hm.samples.void_count == void.sum() and geo.spacing == (5.0, 5.0)
    _valid_exact(hm, np.round(small, 2), void)
    img = write_raster(str(tmp_path / "dem.img"), small.astype(np.float32), driver="HFA")
    _valid_exact(_read(img)[0], small)


def test_a_virtual_mosaic_is_one_terrain_crack_free_across_its_files(tmp_path):
    """A .vrt over two adjacent GeoTIFFs (as gdalbuildvrt writes it) reads as the whole DEM, and equals the two
    files picked together."""
    top = _heights(100, 160).astype(np.float32)
    left = write_raster(str(tmp_path / "left.tif"), top[:, :80])
    right = write_raster(str(tmp_path / "right.tif"), top[:, 80:], corner=(500000.0 + 80 * 30.0, 4600000.0))
    sources = "".join(f"""
    <SimpleSource><SourceFilename relativeToVRT="1">{name}</SourceFilename><SourceBand>1</SourceBand>
      <SrcRect xOff="0" yOff="0" xSize="80" ySize="100"/><DstRect xOff="{x}" yOff="0" xSize="80" ySize="100"/>
    </SimpleSource>""" for name, x in (("left.tif", 0), ("right.tif", 80)))
    (tmp_path / "dem.vrt").write_text(f"""<VRTDataset rasterXSize="160" rasterYSize="100">
  <SRS>EPSG:32633</SRS><GeoTransform>500000, 30, 0, 4600000, 0, -30</GeoTransform>
  <VRTRasterBand dataType="Float32" band="1">{sources}
  </VRTRasterBand>
</VRTDataset>""")
    whole, geo = _read(tmp_path / "dem.vrt")
    _valid_exact(whole, top.astype(np.float64))
    pair, _ = gt.read_geotiff([left, right])
    assert whole.heights().tobytes() == pair.heights().tobytes()
    t1, t2 = ta.tile_table(whole, 32, backend="numpy"), ta.tile_table(pair, 32, backend="numpy")
    assert np.array_equal(t1.ham_max, t2.ham_max)


def test_a_picture_is_refused_unless_a_band_is_chosen(tmp_path):
    rgb = (np.random.default_rng(1).random((3, 40, 50)) * 255).astype(np.uint8)
    path = write_raster(str(tmp_path / "photo.tif"), rgb, PHOTOMETRIC="RGB")
    with pytest.raises(InvalidInputError, match=r"photo\.tif is a picture .*Band"):
        gt.read_geotiff([path])
    hm, _ = gt.read_geotiff([path], band=2)
    assert np.array_equal(hm.heights()[::-1], rgb[1].astype(np.float32))
    with pytest.raises(InvalidInputError, match="Band 4 does not exist"):
        gt.read_geotiff([path], band=4)


def test_rotated_and_south_up_rasters_are_warped_north_up(tmp_path):
    """A plane z = a x + b y + c written on a rotated grid and on south-up rows: the north-up warp (bilinear) keeps
    the plane, and the extent stays that of the data."""
    a, b, c = 0.02, -0.015, 300.0
    h, w = 80, 100
    rotated = Affine.translation(1000.0, 5000.0) @ Affine.rotation(20.0) @ Affine.scale(10.0, -10.0)
    for name, transform in (("rot", rotated), ("south", Affine(10.0, 0, 1000.0, 0, 10.0, 4200.0))):
        cols, rows = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
        x = transform.a * cols + transform.b * rows + transform.c
        y = transform.d * cols + transform.e * rows + transform.f
        path = write_raster(str(tmp_path / f"{name}.tif"), (a * x + b * y + c).astype(np.float32),
                            transform=transform)
        hm, geo = _read(path, voids="HOLES")
        assert "warped north up" in " ".join(geo.files[0].notes)
        heights = hm.heights()[::-1]
        gx = geo.origin[0] + np.arange(hm.width) * geo.spacing[0]
        gy = geo.origin[1] - np.arange(hm.height) * geo.spacing[1]
        plane = a * gx[None, :] + b * gy[:, None] + c
        valid = ~hm.void_at(*np.meshgrid(np.arange(hm.width, dtype=float), np.arange(hm.height, dtype=float)))[::-1]
        assert valid.mean() > (0.5 if name == "rot" else 0.99)
        inner = valid.copy()  # two samples in from the data's edge, where bilinear weights lean on the outside
        for axis in (0, 1):
            for shift in (-2, -1, 1, 2):
                inner &= np.roll(valid, shift, axis=axis)
        assert inner.sum() > 0.8 * valid.sum() - 4 * (hm.width + hm.height)
        np.testing.assert_allclose(heights[inner], plane[inner], atol=1e-3)
        corners = np.array([[0, 0], [w, 0], [0, h], [w, h]], float)
        xs = transform.a * corners[:, 0] + transform.b * corners[:, 1] + transform.c
        ys = transform.d * corners[:, 0] + transform.e * corners[:, 1] + transform.f
        span = (xs.max() - xs.min(), ys.max() - ys.min())
        got = (hm.width * geo.spacing[0], hm.height * geo.spacing[1])
        assert got == pytest.approx(span, rel=0.005 + geo.spacing[0] / span[0])


def test_without_gdal_what_only_gdal_resolves_is_refused_with_that_reason(tmp_path, monkeypatch):
    """The TIFF reader (a zip without GDAL) never guesses: a unit named only by an EPSG code it does not list and a
    mask band are refused, naming why; a UTM file (metres by its code) is read."""
    monkeypatch.setattr(gdal_raster, "why_not", lambda: "rasterio is not installed (a test)")
    top = _heights(40, 50).astype(np.float32)
    feet = write_raster(str(tmp_path / "ft.tif"), top, crs="EPSG:2227+6360", corner=(6000000.0, 2000000.0))
    with pytest.raises(InvalidInputError, match=r"ft\.tif names its unit only through EPSG code 2227.*GDAL.*"
                                                r"rasterio is not installed"):
        gt.read_geotiff([feet])
    masked = write_raster(str(tmp_path / "m.tif"), top, mask=~_voids(40, 50))
    with pytest.raises(InvalidInputError, match=r"m\.tif marks its voids with a mask band.*GDAL"):
        gt.read_geotiff([masked])
    hm, geo = _read(write_raster(str(tmp_path / "utm.tif"), top, crs="EPSG:32633"), "tiff")
    _valid_exact(hm, top.astype(np.float64))
    with pytest.raises(InvalidInputError, match=r"dem\.asc: this Tessera reads only GeoTIFF files.*rasterio"):
        gt.read_geoinfo(str(tmp_path / "dem.asc"))


def test_what_gdal_cannot_read_is_refused_with_gdals_reason(tmp_path):
    (tmp_path / "junk.tif").write_bytes(b"II*\x00garbage")
    with pytest.raises(InvalidInputError, match=r"GDAL cannot open junk\.tif: .*TIFF"):
        gt.read_geotiff([str(tmp_path / "junk.tif")])
    (tmp_path / "notes.txt").write_text("not a raster")
    with pytest.raises(InvalidInputError, match=r"GDAL cannot open notes\.txt: .*not recognized"):
        gt.read_geotiff([str(tmp_path / "notes.txt")])
    top = _heights(64, 64).astype(np.float32)
    good = write_raster(str(tmp_path / "cut.tif"), top, TILED=True, BLOCKXSIZE=32, BLOCKYSIZE=32, COMPRESS="DEFLATE")
    size = (tmp_path / "cut.tif").stat().st_size
    with open(good, "r+b") as f:
        f.truncate(size - 400)  # the last tile's bytes are gone
    with pytest.raises(InvalidInputError, match=r"Reading rows .* of cut\.tif failed: "):
        gt.read_geotiff([good])[0].heights()
    assert gdal_raster.available() and gdal_raster.why_not() == ""


def test_a_whole_metre_dem_of_a_smooth_surface_is_no_rougher_than_the_same_surface_as_float(tmp_path):
    """Rounding to whole metres makes terraces; the analysis discounts the most HAM rounding can make, so the
    integer DEM gets no more triangles than the float one (within 5 %) from any camera, while the undiscounted
    analysis would mesh the terraces."""
    from dataclasses import replace

    from tessera.kernels.common.camera import Camera
    from tessera.kernels.terrain import lod as tl
    from tessera.kernels.terrain import mesh as tm

    n = 257
    y, x = np.mgrid[0:n, 0:n] / (n - 1)
    top = 400.0 + 180.0 * np.sin(2.1 * x + 0.4) * np.cos(1.7 * y) + 60.0 * x  # smooth hills, 30 m samples
    as_float, _ = _read(write_raster(str(tmp_path / "f.tif"), top.astype(np.float32)))
    as_int, geo = _read(write_raster(str(tmp_path / "i.tif"), np.round(top).astype(np.int16)))
    assert geo.files[0].quantum == 1.0 and as_int.quantum == 1.0 and as_float.quantum == 0.0
    assert np.array_equal(as_int.heights(), np.round(top[::-1]).astype(np.float32))  # the mesh keeps the file's values
    tables = {name: ta.tile_table(hm, 32, backend="numpy") for name, hm in (("float", as_float), ("int", as_int))}
    raw = ta.tile_table(replace(as_int, quantum=0.0), 32, backend="numpy")
    rng = np.random.default_rng(11)
    for _ in range(5):
        eye = (rng.uniform(-6000, 6000), rng.uniform(-6000, 6000), rng.uniform(800, 4000))
        cam = Camera.looking_at(eye, (0.0, 0.0, 400.0), width=1280, height=720, far=1e6)
        count = {}
        for name, hm, table in (("float", as_float, tables["float"]), ("int", as_int, tables["int"]),
                                ("raw", as_int, raw)):
            sel = tl.select(hm, table, cam, tl.TerrainLod(levels="FRACTIONAL", culling=False))
            count[name] = tm.triangle_count(sel)
        assert count["int"] <= 1.05 * count["float"], count
        assert count["raw"] > 1.3 * count["float"], count  # without the discount the terraces would be meshed

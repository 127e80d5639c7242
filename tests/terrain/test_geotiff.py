"""GeoTIFF elevation data: placement and units from the tags, exact heights, voids filled or cut (never a height),
several files as one terrain bit for bit, bounded memory, bad files refused by name."""

import tracemalloc

import numpy as np
import pytest
from tessera.kernels.common.camera import Camera
from tessera.kernels.common.errors import BudgetError, InvalidInputError
from tessera.kernels.terrain import analysis as ta
from tessera.kernels.terrain import gdal_raster, sample_grid, void_fill
from tessera.kernels.terrain import geotiff as gt
from tessera.kernels.terrain import lod as tl
from tessera.kernels.terrain import mesh as tm
from tessera.tools.geotiff_files import write_geotiff
from test_terrain_lod import _random_camera

from tools.ridged_terrain import ridged_terrain

NODATA = -32768


def _dem(h=200, w=300, seed=0, relief=1800.0):
    """Heights in metres, top row first (as files store them): float32."""
    return (ridged_terrain(max(h, w), seed=seed, octaves=6)[:h, :w] * relief + 120.0).astype(np.float32)


def _with_voids(top_first, fill):
    d = top_first.copy()
    d[40:55, 60:90] = fill  # a lake
    d[0:3, 200:230] = fill  # a void on the northern edge
    d[120, 10] = fill  # one bad sample
    return d


@pytest.mark.parametrize("dtype, layout", [("float32", "tiled"), ("int16", "tiled"), ("float32", "strips"),
                                           ("int16", "strips"), ("int16", "predictor")])
def test_placement_texels_and_every_valid_height_exact(tmp_path, dtype, layout, elevation_reader):
    top = _dem()
    data = top.astype(np.int16) if dtype == "int16" else top
    tile = (64, 32) if layout == "tiled" else None
    predictor = 2 if layout == "predictor" else None  # horizontal differencing, as GDAL writes with PREDICTOR=2
    path = write_geotiff(str(tmp_path / "dem.tif"), data, spacing=(30.0, 30.0), corner=(500000.0, 4600000.0),
                         tile=tile, rowsperstrip=7, predictor=predictor)
    hm, geo = gt.read_geotiff([path])
    assert (hm.width, hm.height) == (300, 200) and hm.texel == (30.0, 30.0)
    assert geo.origin == (500015.0, 4599985.0)  # PixelIsArea: the first sample at its pixel's centre
    assert geo.centre == (500015.0 + 149.5 * 30, 4599985.0 - 99.5 * 30)
    want = data[::-1].astype(np.float32)  # row 0 at the bottom (south)
    assert np.array_equal(hm.heights(), want)
    rng = np.random.default_rng(1)
    ys, xs = rng.integers(0, 200, 500), rng.integers(0, 300, 500)
    assert np.array_equal(hm.sample(xs.astype(float), ys.astype(float)), want[ys, xs])


def test_units_point_rasters_transforms_and_geographic_spacing(tmp_path, elevation_reader):
    top = _dem(60, 80)
    feet = write_geotiff(str(tmp_path / "feet.tif"), top, spacing=(3.0, 3.0), linear=9002, vertical=9002, point=True,
                         corner=(1000.0, 2000.0))
    hm, geo = gt.read_geotiff([feet])
    assert geo.origin == (1000.0, 2000.0)  # PixelIsPoint: the tie point is the sample
    assert hm.texel == pytest.approx((0.9144, 0.9144), rel=1e-12) and hm.unit == pytest.approx(0.3048, rel=1e-12)
    assert np.allclose(hm.heights(), top[::-1] * 0.3048, rtol=1e-6)
    matrix = np.array([[2.0, 0, 0, 100.0], [0, -2.0, 0, 900.0], [0, 0, 0, 0], [0, 0, 0, 1]])
    hm, geo = gt.read_geotiff([write_geotiff(str(tmp_path / "m.tif"), top, transform=matrix)])
    assert hm.texel == (2.0, 2.0) and geo.origin == (101.0, 899.0)
    # one arc-second at 46.5 N: metres per degree on WGS 84 (prime vertical and meridional radii)
    arc = 1 / 3600
    geo_path = write_geotiff(str(tmp_path / "srtm.tif"), top, spacing=(arc, arc), geographic=True,
                             corner=(7.0, 46.5 + 30 * arc))  # 60 rows: the centre 30 rows down
    hm, geo = gt.read_geotiff([geo_path])
    tx, ty = hm.texel
    assert tx == pytest.approx(21.3, abs=0.05) and ty == pytest.approx(30.87, abs=0.02)
    assert geo.centre[1] == pytest.approx(46.5, abs=1e-9)
    world = tl.to_world(hm, np.array([0.0, 79.0]), np.array([0.0, 59.0]), np.zeros(2))
    assert world[1, 0] - world[0, 0] == pytest.approx(79 * tx) and world[1, 1] - world[0, 1] == pytest.approx(59 * ty)


def test_pull_push_keeps_valid_bits_and_fills_within_the_valid_range():
    rng = np.random.default_rng(3)
    values = rng.normal(size=(70, 90)) * 10 + 50
    valid = rng.random((70, 90)) > 0.3
    valid[10:40, 20:70] = False  # a large void
    out = void_fill.pull_push(values, valid)
    assert np.array_equal(out[valid], values[valid].astype(np.float32))
    assert out[~valid].min() >= values[valid].min() - 1e-3 and out[~valid].max() <= values[valid].max() + 1e-3
    ramp = np.add.outer(np.arange(70.0), 2 * np.arange(90.0))
    filled = void_fill.pull_push(ramp, valid)
    assert np.abs(filled - ramp)[~valid].max() < 0.2 * np.ptp(ramp)  # a smooth guess, near the plane it cuts


def test_cells_are_labelled_by_8_connected_components():
    m = np.zeros((6, 7), bool)
    m[0, 0] = m[1, 1] = True  # diagonal neighbours: one component
    m[4:6, 4:7] = True
    m[0, 6] = True
    labels, n = void_fill.label_cells(m)
    assert n == 3 and labels[0, 0] == labels[1, 1] and len({labels[0, 0], labels[5, 6], labels[0, 6]}) == 3
    assert (labels[~m] == 0).all()
    assert void_fill.label_cells(np.ones((3, 3), bool))[1] == 1 and void_fill.label_cells(m & False)[1] == 0


@pytest.mark.parametrize("dtype, fill", [("int16", NODATA), ("float32", -9999.0), ("float32", "nan")])
def test_voids_never_become_heights(tmp_path, dtype, fill, elevation_reader):
    top = _dem()
    value = np.nan if fill == "nan" else fill
    data = _with_voids(top, value).astype(dtype)
    path = write_geotiff(str(tmp_path / "v.tif"), data, nodata=fill, tile=(32, 32))
    hm, _ = gt.read_geotiff([path])
    h = hm.heights()
    void = _with_voids(np.zeros_like(top), 1.0)[::-1] == 1.0
    valid_values = data[::-1][~void].astype(np.float32)
    assert np.isfinite(h).all() and np.array_equal(h[~void], valid_values)
    assert h[void].min() >= valid_values.min() and h[void].max() <= valid_values.max()
    table = ta.tile_table(hm, 32, backend="numpy")
    assert table.h_min.min() >= valid_values.min() and table.h_max.max() <= valid_values.max()
    rows = np.concatenate([hm.rows(y, min(200, y + 37)) for y in range(0, 200, 37)])  # bands agree with points
    assert np.array_equal(rows, h)


def test_holes_cut_exactly_the_triangles_on_voids_from_random_cameras(tmp_path):
    top = _with_voids(_dem(), NODATA).astype(np.int16)
    path = write_geotiff(str(tmp_path / "h.tif"), top, nodata=NODATA)
    filled, _ = gt.read_geotiff([path], voids="FILL")
    holes, _ = gt.read_geotiff([path], voids="HOLES")
    void = top[::-1] == NODATA
    ta_fill, ta_holes = ta.tile_table(filled, 32, backend="numpy"), ta.tile_table(holes, 32, backend="numpy")
    assert np.array_equal(ta_fill.ham_max, ta_holes.ham_max)  # the analysis sees the same filled ground
    rng = np.random.default_rng(5)
    for _ in range(6):
        cam = _random_camera(rng, filled, lowest=500.0, target_z=1000.0, far=40.0)  # over 1 km of relief
        sel = tl.select(filled, ta_fill, cam, tl.TerrainLod(levels="FRACTIONAL", culling=False))
        a, b = tm.bake(filled, ta_fill, sel), tm.bake(holes, ta_fill, sel)
        corners = a.samples[a.triangles]  # (m, 3, 2)
        x, y = corners[..., 0], corners[..., 1]
        touches = np.zeros(x.shape, bool)
        for fy in (np.floor, np.ceil):
            for fx in (np.floor, np.ceil):
                touches |= void[fy(y).astype(int), fx(x).astype(int)]
        keep = ~touches.any(axis=1)
        assert 0 < keep.sum() < len(keep)
        # the holes mesh is the filled mesh less those triangles: the same welded vertices, so no crack
        assert np.array_equal(np.sort(b.samples[b.triangles].reshape(-1, 6), axis=0),
                              np.sort(corners[keep].reshape(-1, 6), axis=0))
        assert np.array_equal(b.positions, a.positions[np.isin(np.arange(len(a.positions)),
                                                               a.triangles[keep].ravel())])


@pytest.mark.parametrize("overlap", [0, 1])
def test_a_dem_split_over_four_files_is_the_single_file_bit_for_bit(tmp_path, overlap, elevation_reader):
    """Adjacent tiles, with or without SRTM's shared border row and column; a void crosses the split."""
    top = _with_voids(_dem(), NODATA).astype(np.int16)
    top[95:110, 140:170] = NODATA  # across the four-way corner
    whole = write_geotiff(str(tmp_path / "whole.tif"), top, nodata=NODATA, tile=(32, 32))
    parts = []
    for i, (r0, r1) in enumerate(((0, 100 + overlap), (100, 200))):
        for j, (c0, c1) in enumerate(((0, 150 + overlap), (150, 300))):
            corner = (500000.0 + c0 * 30.0, 4600000.0 - r0 * 30.0)
            parts.append(write_geotiff(str(tmp_path / f"part_{i}{j}.tif"), top[r0:r1, c0:c1], nodata=NODATA,
                                       corner=corner, tile=(16, 16)))
    for voids in ("FILL", "HOLES"):
        one, geo1 = gt.read_geotiff([whole], voids=voids)
        four, geo4 = gt.read_geotiff(parts[::-1], voids=voids)
        assert geo1.origin == geo4.origin and (one.width, one.height) == (four.width, four.height)
        assert one.heights().tobytes() == four.heights().tobytes()
        t1, t4 = ta.tile_table(one, 32, backend="numpy"), ta.tile_table(four, 32, backend="numpy")
        cam = Camera.looking_at((-3000.0, -4000.0, 5000.0), (0.0, 0.0, 900.0), width=800, height=600, far=1e6)
        s1 = tl.select(one, t1, cam, tl.TerrainLod())
        m1, m4 = tm.bake(one, t1, s1), tm.bake(four, t4, tl.select(four, t4, cam, tl.TerrainLod()))
        assert m1.positions.tobytes() == m4.positions.tobytes() and np.array_equal(m1.triangles, m4.triangles)


def test_a_gap_between_files_is_a_void(tmp_path, elevation_reader):
    top = _dem(64, 64)
    a = write_geotiff(str(tmp_path / "a.tif"), top[:, :20], corner=(0.0, 640.0), spacing=(10.0, 10.0))
    b = write_geotiff(str(tmp_path / "b.tif"), top[:, 40:], corner=(400.0, 640.0), spacing=(10.0, 10.0))
    hm, _ = gt.read_geotiff([a, b], voids="HOLES")
    assert hm.width == 64 and np.array_equal(hm.heights()[:, :20], top[::-1, :20])
    assert hm.void_at(np.array([30.0, 5.0]), np.array([10.0, 10.0])).tolist() == [True, False]


def test_out_of_core_analysis_keeps_its_memory_bounded(tmp_path, monkeypatch, elevation_reader):
    """A 1025 x 16385 float32 map (64 MiB as float32) is scanned and analysed with at most a tenth of that
    allocated: the memory follows the width (a few bands and two decoded blocks), not the size."""
    w, h = 1025, 16385
    monkeypatch.setattr(sample_grid, "CACHE_BYTES", 2**20)
    monkeypatch.setattr(gdal_raster, "CACHE_BYTES", 2**20)
    block = ridged_terrain(w, seed=4, octaves=5) * 900.0
    heights = np.concatenate([block, block[::-1]] * 8)[:h]
    heights[2000:2040, 100:180] = np.nan
    path = write_geotiff(str(tmp_path / "big.tif"), heights, tile=(256, 256), nodata="nan")
    del heights, block
    tracemalloc.start()
    try:
        hm, _ = gt.read_geotiff([path])
        table = ta.tile_table(hm, 64, backend="numpy")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert table.counts == (16, 256) and np.isfinite(table.h_min).all()
    assert peak < w * h * 4 / 10, f"peak {peak / 2**20:.1f} MiB"


def test_bad_geotiffs_are_refused_with_the_file_and_the_reason(tmp_path, monkeypatch):
    """The TIFF reader's refusals (GDAL's, and the rasters it warps instead, are in test_gdal_rasters.py)."""
    monkeypatch.setattr(gdal_raster, "why_not", lambda: "rasterio is not installed (a test)")
    top = _dem(40, 50)

    def refused(path, *words, **kw):
        with pytest.raises(InvalidInputError) as err:
            gt.read_geotiff([path], **kw)
        text = str(err.value)
        assert all(w in text for w in words), text

    rotated = np.array([[2.0, 0.5, 0, 100.0], [0.5, -2.0, 0, 900.0], [0, 0, 0, 0], [0, 0, 0, 1]])
    refused(write_geotiff(str(tmp_path / "rot.tif"), top, transform=rotated), "rot.tif", "rotated")
    south_up = np.array([[2.0, 0, 0, 100.0], [0, 2.0, 0, 900.0], [0, 0, 0, 0], [0, 0, 0, 1]])
    refused(write_geotiff(str(tmp_path / "south.tif"), top, transform=south_up), "south.tif", "south to north")
    refused(write_geotiff(str(tmp_path / "noscale.tif"), top, pixel_scale=False), "noscale.tif", "ModelPixelScale")
    refused(write_geotiff(str(tmp_path / "warp.tif"), top, tiepoints=[0, 0, 0, 1, 2, 0, 10, 10, 0, 5, 6, 0]),
            "warp.tif", "tie points")
    refused(write_geotiff(str(tmp_path / "units.tif"), top, linear=9999), "units.tif", "9999")
    everywhere = np.full_like(top, -9999.0)
    refused(write_geotiff(str(tmp_path / "empty.tif"), everywhere, nodata=-9999), "empty.tif", "no-data")
    plain = str(tmp_path / "plain.tif")
    import tifffile

    tifffile.imwrite(plain, top)
    assert gt.read_geoinfo(plain) is None
    refused(plain, "plain.tif", "no GeoTIFF tags")
    with pytest.raises(InvalidInputError, match="not a TIFF"):
        (tmp_path / "junk.tif").write_bytes(b"II*\x00garbage")
        gt.read_geotiff([str(tmp_path / "junk.tif")])
    # an unknown compression: the tag of a good file changed to a code no reader knows
    good = write_geotiff(str(tmp_path / "codec.tif"), top, tile=None, rowsperstrip=40, compression=None)
    raw = bytearray(open(good, "rb").read())
    with tifffile.TiffFile(good) as tf:
        offset = tf.pages.first.tags["Compression"].valueoffset
    raw[offset:offset + 2] = (34999).to_bytes(2, "little")
    open(good, "wb").write(bytes(raw))
    with pytest.raises(InvalidInputError, match="codec.tif") as err:
        gt.read_geotiff([good])
    assert "34999" in str(err.value) or "ompression" in str(err.value)
    a = write_geotiff(str(tmp_path / "a.tif"), top, spacing=(30.0, 30.0))
    b = write_geotiff(str(tmp_path / "b.tif"), top, spacing=(10.0, 10.0), corner=(600000.0, 4600000.0))
    with pytest.raises(InvalidInputError, match="spacing"):
        gt.read_geotiff([a, b])
    c = write_geotiff(str(tmp_path / "c.tif"), top, corner=(500000.0 + 45.0, 4600000.0))
    with pytest.raises(InvalidInputError, match="same grid"):
        gt.read_geotiff([a, c])


def test_a_void_too_large_for_the_budget_is_refused_with_the_numbers(tmp_path, elevation_reader):
    top = _dem(256, 256)
    top[10:240, 10:240] = NODATA
    path = write_geotiff(str(tmp_path / "sea.tif"), top.astype(np.int16), nodata=NODATA)
    with pytest.raises(BudgetError, match="Holes"):
        gt.read_geotiff([path], budget_bytes=2**20)
    hm, _ = gt.read_geotiff([path], budget_bytes=64 * 2**20)
    assert np.isfinite(hm.heights()).all()
    # cut out, the void needs no fill of its own: the analysis sees the mean of the ground around it
    holes, _ = gt.read_geotiff([path], budget_bytes=2**20, voids="HOLES")
    inside = holes.heights()[::-1][10:240, 10:240]
    ring = top[:, :].astype(np.float64)[top != NODATA]
    assert np.ptp(inside) == 0 and ring.min() <= inside[0, 0] <= ring.max()
    assert holes.void_at(np.array([100.0]), np.array([100.0]))[0]


@pytest.mark.parametrize("compression, fmt", [("lzw", "int16"), ("lzw", "float"), ("zip", "float"), ("none", "uint16")])
def test_blocks_and_points_read_every_compression_and_layout(tmp_path, compression, fmt):
    """TIFFs written by OpenImageIO itself (LZW, deflate with its predictor, none), tiled and striped: bands across
    block borders and scattered points give the written samples."""
    import OpenImageIO as oiio

    rng = np.random.default_rng(8)
    if fmt == "uint16":
        data = rng.integers(0, 65535, (300, 170)).astype(np.uint16)
    else:
        data = (rng.normal(size=(300, 170)) * 900).astype(np.int16 if fmt == "int16" else np.float32)
    for tiled in (True, False):
        path = str(tmp_path / f"{compression}_{tiled}.tif")
        spec = oiio.ImageSpec(170, 300, 1, fmt)
        spec.attribute("compression", compression)
        if tiled:
            spec.tile_width = spec.tile_height = 32
        out = oiio.ImageOutput.create(path)
        assert out.open(path, spec) and out.write_image(data[..., None])
        out.close()
        layout = sample_grid.tiff_layout(path)
        assert layout.tiled == tiled and (layout.width, layout.height) == (170, 300)
        source = sample_grid.TiffSource(path, layout)
        assert np.array_equal(source.rows(0, 300), data.astype(np.float32))
        assert np.array_equal(source.rows(250, 290), data[250:290].astype(np.float32))  # across a block border
        ys, xs = rng.integers(0, 300, 400), rng.integers(0, 170, 400)
        assert np.array_equal(source.points(ys, xs), data[ys, xs].astype(np.float32))

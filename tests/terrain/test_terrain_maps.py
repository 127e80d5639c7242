"""Terrain height maps in, and their analysis: precision kept, clear errors, HAM identities, tile table."""

import numpy as np
import pytest
from tessera.kernels.common.errors import InvalidInputError, TesseraError
from tessera.kernels.terrain import analysis as ta
from tessera.kernels.terrain import heightmap_io as hio
from tessera.tools.generators import random_ham_case


def _write(path, data, fmt):
    import OpenImageIO as oiio

    h, w = data.shape
    out = oiio.ImageOutput.create(path)
    assert out.open(path, oiio.ImageSpec(w, h, 1, fmt))
    assert out.write_image(np.ascontiguousarray(data[::-1])[..., None])  # files store the top row first
    out.close()


@pytest.mark.parametrize("ext,dtype,fmt", [(".png", np.uint8, "uint8"), (".png", np.uint16, "uint16"),
                                           (".tif", np.uint16, "uint16"), (".tif", np.float32, "float"),
                                           (".exr", np.float32, "float")])
def test_image_height_maps_keep_their_precision(tmp_path, ext, dtype, fmt):
    rng = np.random.default_rng(3)
    if dtype == np.float32:
        data = rng.normal(0, 100, (37, 53)).astype(np.float32)
    else:
        data = rng.integers(0, np.iinfo(dtype).max + 1, (37, 53)).astype(dtype)
    path = str(tmp_path / f"h{ext}")
    _write(path, data, fmt)
    hm = hio.read_heightmap(path, texel_size=2.0, scale=500.0, offset=-10.0)
    assert hm.samples.dtype == dtype and np.array_equal(hm.samples, data)  # exact, row 0 = bottom
    step = 500.0 / (255 if dtype == np.uint8 else 65535) if dtype != np.float32 else 500.0
    assert hm.heights()[5, 7] == pytest.approx(-10.0 + step * float(data[5, 7]), rel=1e-6)


def test_raw_r16_is_memory_mapped_and_checked_for_size(tmp_path):
    data = np.random.default_rng(5).integers(0, 65536, (40, 24)).astype("<u2")
    path = tmp_path / "h.r16"
    data[::-1].tofile(path)  # top row first, as r16 files are
    hm = hio.read_heightmap(str(path), raw_size=(24, 40), scale=100.0)
    assert isinstance(hm.samples.base, np.memmap) or isinstance(hm.samples, np.memmap)
    assert np.array_equal(hm.samples, data)
    with pytest.raises(InvalidInputError, match="give its width and height"):
        hio.read_heightmap(str(path))
    with pytest.raises(InvalidInputError, match="bytes"):
        hio.read_heightmap(str(path), raw_size=(25, 40))
    square = tmp_path / "s.r16"
    np.zeros((32, 32), "<u2").tofile(square)
    with pytest.raises(InvalidInputError, match="32x32"):
        hio.read_heightmap(str(square), raw_size=(16, 16))


def test_raw_r32_nan_and_bad_files_are_refused(tmp_path):
    data = np.zeros((8, 8), "<f4")
    data[3, 4] = np.nan
    path = tmp_path / "h.r32"
    data.tofile(path)
    with pytest.raises(InvalidInputError, match="NaN"):
        hio.read_heightmap(str(path), raw_size=(8, 8))
    with pytest.raises(TesseraError, match="No such"):
        hio.read_heightmap(str(tmp_path / "missing.png"))
    junk = tmp_path / "junk.png"
    junk.write_bytes(b"not an image at all")
    with pytest.raises(TesseraError):
        hio.read_heightmap(str(junk))
    with pytest.raises(InvalidInputError, match="Unsupported"):
        hio.read_heightmap(str(tmp_path / "h.jpg2"))
    with pytest.raises(InvalidInputError, match="2x2"):
        hio.from_array(np.zeros((1, 5), np.float32))


def test_bilinear_sample_reads_only_neighbours_and_interpolates():
    hm = hio.from_array(np.arange(12, dtype=np.uint16).reshape(3, 4), scale=65535.0)
    assert hm.sample(1.5, 1.0) == pytest.approx(5.5)
    assert hm.sample(3.0, 2.0) == pytest.approx(11.0)  # the far corner
    assert hm.sample(0.25, 0.5) == pytest.approx(0.25 + 2.0)


def test_ham_of_constant_is_zero_and_of_a_ramp_zero_inside():
    assert ta.ham(np.full((20, 30), 7.5, np.float32)).max() == 0.0
    y, x = np.mgrid[0:40, 0:50].astype(np.float32)
    ramp = 0.3 * x + 0.7 * y
    m = ta.sobel_magnitude(np.pad(ramp, ((1, 1), (0, 0)), mode="edge"))
    inside = ta.ham(ramp)[2:-2, 2:-2]
    assert inside.max() <= 64 * np.finfo(np.float32).eps * ramp.max()  # zero up to float32 rounding of H
    assert m.max() > 1e4 * inside.max()
    assert ta.ham(ramp).max() > 1.0  # the clamped border is not a ramp


def test_ham_concentrates_along_a_cliff():
    h = np.zeros((40, 60), np.float32)
    h[:, 30:] = 10.0
    a = ta.ham(h)
    cols = np.nonzero(a.max(axis=0) > 0)[0]
    assert cols.min() >= 30 - 3 and cols.max() <= 30 + 2  # two Sobel passes reach two samples each side
    assert a[:, :26].max() == 0 and a[:, 33:].max() == 0 and a.max() > 0


def _brute_table(h_world, ham, ts):
    rows, cols = h_world.shape
    nty, ntx = -(-(rows - 1) // ts), -(-(cols - 1) // ts)
    out = {k: np.zeros((nty, ntx)) for k in ("ham_max", "h_min", "h_max", "peak_x", "peak_y")}
    for ty in range(nty):
        for tx in range(ntx):
            y0, y1, x0, x1 = ty * ts, min(ty * ts + ts, rows - 1), tx * ts, min(tx * ts + ts, cols - 1)
            block = h_world[y0:y1 + 1, x0:x1 + 1]
            out["ham_max"][ty, tx] = ham[y0:y1 + 1, x0:x1 + 1].max()
            out["h_min"][ty, tx], out["h_max"][ty, tx] = block.min(), block.max()
            iy, ix = np.unravel_index(np.argmax(block), block.shape)
            out["peak_x"][ty, tx], out["peak_y"][ty, tx] = x0 + ix, y0 + iy
    return out


@pytest.mark.parametrize("shape,ts", [((70, 90), 16), ((65, 65), 64), ((33, 100), 8)])
def test_tile_table_matches_a_brute_force_reduction(shape, ts):
    rng = np.random.default_rng(shape[0])
    data = rng.integers(0, 200, shape).astype(np.uint8)
    data[5, 5] = data[5, 6] = 255  # ties: the first in row-major order wins
    hm = hio.from_array(data, texel_size=0.5, scale=255.0 * 3)
    table = ta.tile_table(hm, ts, backend="numpy")
    ref = _brute_table(hm.heights(), ta.ham(hm.heights() / 0.5), ts)
    for key, want in ref.items():
        assert np.array_equal(getattr(table, key), want.astype(getattr(table, key).dtype)), key
    assert table.rgba().shape == table.ham_max.shape + (4,)


def test_an_edit_re_analyses_only_reachable_tiles_and_matches_a_full_pass():
    rng = np.random.default_rng(8)
    h = rng.normal(0, 5, (130, 161)).astype(np.float32)
    table = ta.tile_table(hio.from_array(h), 32, backend="numpy")
    for _ in range(6):
        x0, y0 = rng.integers(0, 150), rng.integers(0, 120)
        x1, y1 = min(161, x0 + rng.integers(1, 40)), min(130, y0 + rng.integers(1, 40))
        h[y0:y1, x0:x1] += rng.normal(0, 3)
        tx0, ty0, tx1, ty1 = ta.update_tiles(table, hio.from_array(h), (x0, y0, x1, y1))
        full = ta.tile_table(hio.from_array(h), 32, backend="numpy")
        for key in ("ham_max", "h_min", "h_max", "peak_x", "peak_y"):
            assert np.array_equal(getattr(table, key), getattr(full, key)), key
        assert (tx1 - tx0) * (ty1 - ty0) < table.ham_max.size  # not a full re-analysis


def test_out_of_core_raw_map_gives_the_in_memory_table(tmp_path):
    data = np.random.default_rng(2).integers(0, 65536, (97, 129)).astype("<u2")
    path = tmp_path / "big.r16"
    data[::-1].tofile(path)
    mapped = hio.read_heightmap(str(path), raw_size=(129, 97), texel_size=3.0, scale=900.0)
    in_memory = hio.from_array(data.astype(np.uint16), texel_size=3.0, scale=900.0)
    a = ta.tile_table(mapped, 32, backend="numpy")
    b = ta.tile_table(in_memory, 32, backend="numpy")
    for key in ("ham_max", "h_min", "h_max", "peak_x", "peak_y"):
        assert np.array_equal(getattr(a, key), getattr(b, key)), key


@pytest.mark.opencl
def test_opencl_ham_and_tile_table_equal_numpy(opencl):
    """The same float32 operations in the same order, contraction off: the device gives the reference's bytes."""
    from tessera.kernels.terrain import opencl_path as terrain_opencl

    hm, ref = random_ham_case()
    got = terrain_opencl.ham(opencl, hm.heights(), 1.0 / 1.5)
    assert got.tobytes() == ref.tobytes()
    a, b = ta.tile_table(hm, 32, backend="numpy"), ta.tile_table(hm, 32, backend="opencl")
    for key in ("ham_max", "h_min", "h_max", "peak_x", "peak_y"):
        assert getattr(a, key).tobytes() == getattr(b, key).tobytes(), key


def test_messages_name_rows_as_the_file_stores_them_and_raw_byte_counts(tmp_path):
    """NaN is reported at the file's own row (top first); a raw file without a size is told its byte count, and
    that an odd count is not whole samples; a truncated image says why."""
    data = np.zeros((64, 8), "<f4")  # bottom-up rows, as the kernels keep them
    data[53, 2] = np.nan  # file row 64 - 1 - 53 = 10
    path = tmp_path / "h.r32"
    data[::-1].tofile(path)
    with pytest.raises(InvalidInputError, match=r"row 10 \(counted from the top, as stored\), column 2"):
        hio.read_heightmap(str(path), raw_size=(8, 64))
    odd = tmp_path / "odd.r16"
    odd.write_bytes(b"\0" * 1001)
    with pytest.raises(InvalidInputError, match="1001 bytes, an odd count"):
        hio.read_heightmap(str(odd))
    square = tmp_path / "sq.r16"
    np.zeros((16, 16), "<u2").tofile(square)
    with pytest.raises(InvalidInputError, match="256 uint16 samples.*16x16"):
        hio.read_heightmap(str(square))
    good = tmp_path / "t.png"
    _write(str(good), np.arange(64 * 64, dtype=np.uint16).reshape(64, 64), "uint16")
    truncated = tmp_path / "trunc.png"
    truncated.write_bytes(good.read_bytes()[:200])
    with pytest.raises(TesseraError) as err:
        hio.read_heightmap(str(truncated))
    reason = str(err.value).split(str(truncated), 1)[1]
    assert len(reason.strip(" :")) > 5, str(err.value)  # a reason, not an empty string after the colon


@pytest.mark.parametrize("name, label", [("scale", "Height Scale"), ("offset", "Height Offset"),
                                         ("texel_size", "Texel Size")])
def test_absurd_scales_are_refused_with_the_setting_and_its_range(name, label):
    for value in (3e38, -3e38, float("inf"), float("nan")):
        with pytest.raises(InvalidInputError, match=f"{label} must be a finite number between -1e\\+15 and 1e\\+15"):
            hio.from_array(np.zeros((4, 4), np.float32), **{name: value})
    hm = hio.from_array(np.ones((4, 4), np.float32), **{name: 1e15 if name != "offset" else -1e15})
    assert np.isfinite(hm.heights()).all()

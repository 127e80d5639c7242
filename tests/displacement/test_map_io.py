"""Displacement-map files through OpenImageIO: exact EXR round trips, 16-bit quantisation, clear errors."""

import numpy as np
import pytest
from tessera.kernels.common.errors import InvalidInputError, TesseraError
from tessera.kernels.displacement.map_io import read_map, write_map


@pytest.mark.parametrize("channels", [1, 3, 4])
def test_exr_round_trip_is_bit_exact(tmp_path, channels):
    m = np.random.default_rng(channels).normal(size=(33, 47, channels)).astype(np.float32)
    m[0, 0, 0] = np.float32(1e-30)  # denormal-ish and tiny values survive
    path = str(tmp_path / "m.exr")
    assert write_map(path, m) == 0
    back = read_map(path)
    assert back.shape == m.shape and back.tobytes() == m.tobytes()


@pytest.mark.parametrize("ext", [".png", ".tif"])
def test_16bit_files_keep_16_bits_and_report_clipping(tmp_path, ext):
    rng = np.random.default_rng(4)
    m = rng.uniform(-1, 3, size=(20, 30, 1)).astype(np.float32)
    path = str(tmp_path / f"m{ext}")
    clipped = write_map(path, m, low=-1.0, high=2.0)
    assert clipped == np.count_nonzero(m > 2.0)
    back = read_map(path, low=-1.0, high=2.0)
    inside = m <= 2.0
    assert np.abs(back[inside] - m[inside]).max() <= 0.5 * 3.0 / 65535 + 1e-6  # half a 16-bit step
    assert len(np.unique(back)) > 256  # not 8-bit
    assert np.array_equal(read_map(path, channels=3, low=-1.0, high=2.0)[..., 1], back[..., 0])


def test_rows_flip_so_row_zero_is_the_bottom(tmp_path):
    import OpenImageIO as oiio

    m = np.zeros((4, 3, 1), np.float32)
    m[0] = 1.0  # bottom row (Blender)
    path = str(tmp_path / "m.exr")
    write_map(path, m)
    img = oiio.ImageBuf(path)
    assert img.getpixel(0, 3)[0] == 1.0 and img.getpixel(0, 0)[0] == 0.0  # the file's last row is the bottom


def test_bad_files_and_values_are_refused(tmp_path):
    with pytest.raises(TesseraError, match="No such"):
        read_map(str(tmp_path / "missing.exr"))
    junk = tmp_path / "junk.exr"
    junk.write_bytes(b"not an image")
    with pytest.raises(TesseraError):
        read_map(str(junk))
    nan = np.zeros((4, 4, 1), np.float32)
    nan[1, 1] = np.nan
    write_map(str(tmp_path / "nan.exr"), nan)
    with pytest.raises(InvalidInputError, match="NaN"):
        read_map(str(tmp_path / "nan.exr"))
    with pytest.raises(InvalidInputError):
        write_map(str(tmp_path / "m.jpg"), np.zeros((4, 4, 1), np.float32))


def test_writes_are_whole_or_absent(tmp_path, monkeypatch):
    """A missing folder is named; a write that fails at the last step leaves the old file as it was and no
    partial file behind (writes go to a temporary file that replaces the target only when complete)."""
    from tessera.kernels.common import image_io

    m = np.random.default_rng(1).random((16, 20, 1)).astype(np.float32)
    missing = tmp_path / "no" / "such" / "map.exr"
    with pytest.raises(TesseraError, match="folder .* does not exist"):
        write_map(str(missing), m)
    target = tmp_path / "map.exr"
    write_map(str(target), m)
    before = target.read_bytes()

    def disk_full(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(image_io.os, "replace", disk_full)
    with pytest.raises(TesseraError, match="No space left on device"):
        write_map(str(target), m * 2)
    monkeypatch.undo()
    assert target.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["map.exr"]  # no partial file left behind
    assert np.array_equal(read_map(str(target)), m)

"""Displacement maps to and from files with OpenImageIO: 32-bit float EXR (exact) and 16-bit PNG/TIFF.

Maps are (H, W, C) float32 with C in 1, 3, 4 and row 0 at the bottom (Blender's image rows, UV v = 0); files
store the top row first, so rows flip on the way in and out. EXR keeps every float bit. A 16-bit file stores
``(value - low) / (high - low)`` rounded to 65535 steps; `write_map` reports how many values it had to clip.
"""

import os

import numpy as np

from .errors import InvalidInputError, TesseraError
from .map_edit import check_map

FLOAT_EXTENSIONS = (".exr",)
INT16_EXTENSIONS = (".png", ".tif", ".tiff")


_FLOAT_FORMATS = ("float", "half", "double")


def oiio_module():
    """The OpenImageIO module, or a `TesseraError` saying it is missing (a broken install)."""
    try:
        import OpenImageIO as oiio
    except ImportError as err:  # a dependency of the package; only a broken install lacks it
        raise TesseraError(f"OpenImageIO is not available ({err})") from err
    return oiio


def read_pixels(path, what, pixel_type, n_channels=None):
    """Pixels of an image file through OpenImageIO: ``(data (H, W, C) with row 0 at the bottom, the file's
    sample format name)``.

    what: the kind of file, for messages; pixel_type(format) -> the type to read as ("float", "uint16",
    "uint8"), raising for formats the caller refuses; n_channels: read only the first ones (None: all).
    """
    if not os.path.isfile(path):
        raise TesseraError(f"No such {what} file: {path}")
    oiio = oiio_module()
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise TesseraError(f"Cannot read {path}: {oiio.geterror()}")
    try:
        spec = inp.spec()
        fmt = str(spec.format)
        n = n_channels or spec.nchannels
        data = inp.read_image(0, 0, 0, n, pixel_type(fmt))
    finally:
        inp.close()
    if data is None:
        raise TesseraError(f"Reading {path} failed: {oiio.geterror()}")
    return np.asarray(data).reshape(spec.height, spec.width, n)[::-1], fmt


def write_map(path, dmap, low=0.0, high=1.0):
    """Write ``dmap`` to ``path`` (.exr float32, .png/.tif uint16). Returns the number of clipped values."""
    check_map(dmap)
    ext = os.path.splitext(path)[1].lower()
    h, w, c = dmap.shape
    rows = np.ascontiguousarray(dmap[::-1])
    if ext in FLOAT_EXTENSIONS:
        fmt, data, clipped = "float", rows, 0
    elif ext in INT16_EXTENSIONS:
        if not high > low:
            raise InvalidInputError(f"The 16-bit range needs high > low; got {low!r}, {high!r}")
        scaled = (rows.astype(np.float64) - low) / (high - low)
        clipped = int(np.count_nonzero((scaled < 0) | (scaled > 1)))
        fmt, data = "uint16", np.round(np.clip(scaled, 0, 1) * 65535).astype(np.uint16)
    else:
        raise InvalidInputError(f"Write maps as {', '.join(FLOAT_EXTENSIONS + INT16_EXTENSIONS)}; got {path!r}")
    oiio = oiio_module()
    spec = oiio.ImageSpec(w, h, c, fmt)
    if ext == ".exr":
        spec.attribute("compression", "zip")  # lossless
    out = oiio.ImageOutput.create(path)
    if out is None or not out.open(path, spec):
        raise TesseraError(f"Cannot write {path}: {oiio.geterror()}")
    ok = out.write_image(data)
    out.close()
    if not ok:
        raise TesseraError(f"Writing {path} failed: {oiio.geterror()}")
    return clipped


def read_map(path, channels=None, low=0.0, high=1.0):
    """Read a map file as (H, W, C) float32, row 0 at the bottom. Integer files scale to [low, high].

    ``channels`` (1, 3 or 4) selects/pads channels: a grey file read as 3 channels repeats its value; extra
    channels are dropped. Raises `TesseraError` for unreadable files and `InvalidInputError` for NaN.
    """
    data, fmt = read_pixels(path, "map", lambda f: "float" if f in _FLOAT_FORMATS else
                            "uint8" if f == "uint8" else "uint16")
    if fmt not in _FLOAT_FORMATS:
        scale = 255.0 if fmt == "uint8" else 65535.0
        data = (low + data.astype(np.float64) / scale * (high - low)).astype(np.float32)
    data = np.ascontiguousarray(data, np.float32)
    if not np.isfinite(data).all():
        raise InvalidInputError(f"{path} contains NaN or infinite values")
    return _channels(data, channels or (data.shape[2] if data.shape[2] in (1, 3, 4) else 3))


def _channels(data, channels):
    if channels not in (1, 3, 4):
        raise InvalidInputError(f"A map has 1, 3 or 4 channels; asked for {channels}")
    have = data.shape[2]
    if have >= channels:
        return np.ascontiguousarray(data[..., :channels])
    if have == 1:
        return np.ascontiguousarray(np.repeat(data, channels, axis=2))
    pad = np.zeros(data.shape[:2] + (channels - have,), np.float32)
    return np.ascontiguousarray(np.concatenate([data, pad], axis=2))

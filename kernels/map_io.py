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


def oiio_module():
    """The OpenImageIO module, or a `TesseraError` saying it is missing (a broken install)."""
    try:
        import OpenImageIO as oiio
    except ImportError as err:  # a dependency of the package; only a broken install lacks it
        raise TesseraError(f"OpenImageIO is not available ({err})") from err
    return oiio


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
    oiio = oiio_module()
    if not os.path.isfile(path):
        raise TesseraError(f"No such map file: {path}")
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise TesseraError(f"Cannot read {path}: {oiio.geterror()}")
    try:
        spec = inp.spec()
        fmt = str(spec.format)
        if fmt in ("float", "half", "double"):
            data = inp.read_image(0, 0, 0, spec.nchannels, "float")
            scale = None
        else:
            data = inp.read_image(0, 0, 0, spec.nchannels, "uint16" if fmt != "uint8" else "uint8")
            scale = 65535.0 if fmt != "uint8" else 255.0
    finally:
        inp.close()
    if data is None:
        raise TesseraError(f"Reading {path} failed: {oiio.geterror()}")
    data = np.asarray(data).reshape(spec.height, spec.width, spec.nchannels)
    if scale is not None:
        data = (low + data.astype(np.float64) / scale * (high - low)).astype(np.float32)
    data = np.ascontiguousarray(data[::-1], np.float32)
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

"""Displacement maps to and from files with OpenImageIO: 32-bit float EXR (exact) and 16-bit PNG/TIFF.

Maps are (H, W, C) float32 with C in 1, 3, 4 and row 0 at the bottom (Blender's image rows, UV v = 0); files
store the top row first, so rows flip on the way in and out. EXR keeps every float bit. A 16-bit file stores
``(value - low) / (high - low)`` rounded to 65535 steps; `write_map` reports how many values it had to clip.
"""

import os

import numpy as np

from ..common.errors import InvalidInputError
from ..common.image_io import read_pixels, write_pixels
from .map_edit import check_map

FLOAT_EXTENSIONS = (".exr",)
INT16_EXTENSIONS = (".png", ".tif", ".tiff")


_FLOAT_FORMATS = ("float", "half", "double")


def write_map(path, dmap, low=0.0, high=1.0):
    """Write ``dmap`` to ``path`` (.exr float32, .png/.tif uint16). Returns the number of clipped values."""
    check_map(dmap)
    ext = os.path.splitext(path)[1].lower()
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
    write_pixels(path, data, fmt, lossless_exr=ext == ".exr")
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

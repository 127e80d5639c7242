"""Image files through OpenImageIO, shared by height maps (terrain) and displacement maps.

Arrays are (H, W, C) with row 0 at the bottom (Blender's image rows, UV v = 0); files store the top row
first, so rows flip on the way in. Errors are `TesseraError` with OpenImageIO's own reason.
"""

import os

import numpy as np

from .errors import TesseraError


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


def write_pixels(path, rows, fmt, lossless_exr=False):
    """Write ``rows`` (H, W, C), already in file order (top row first), as sample format ``fmt`` ("float",
    "uint16", ...); ``lossless_exr`` sets zip compression."""
    h, w, c = rows.shape
    oiio = oiio_module()
    spec = oiio.ImageSpec(w, h, c, fmt)
    if lossless_exr:
        spec.attribute("compression", "zip")  # lossless
    out = oiio.ImageOutput.create(path)
    if out is None or not out.open(path, spec):
        raise TesseraError(f"Cannot write {path}: {oiio.geterror()}")
    ok = out.write_image(rows)
    out.close()
    if not ok:
        raise TesseraError(f"Writing {path} failed: {oiio.geterror()}")

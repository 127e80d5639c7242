"""Image files through OpenImageIO, shared by height maps (terrain) and displacement maps.

Arrays are (H, W, C) with row 0 at the bottom (Blender's image rows, UV v = 0); files store the top row
first, so rows flip on the way in. Errors are `TesseraError` with OpenImageIO's own reason (or, where it gives
none, what is known: a damaged file, a missing folder). Writes go to a temporary file beside the target that
replaces it only when complete, so a failed write never leaves a half-written file.
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


def _open(path, what):
    """``(oiio module, ImageInput)`` for ``path``, or a `TesseraError` saying why it cannot be opened."""
    if not os.path.isfile(path):
        raise TesseraError(f"No such {what} file: {path}")
    oiio = oiio_module()
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise TesseraError(f"Cannot read {path}: {_reason(oiio, None, 'not an image file OpenImageIO can read')}")
    return oiio, inp


def image_size(path, what="image"):
    """``(width, height, channels)`` of an image file, from its header only (nothing is read)."""
    _, inp = _open(path, what)
    try:
        spec = inp.spec()
        return spec.width, spec.height, spec.nchannels
    finally:
        inp.close()


def read_pixels(path, what, pixel_type, n_channels=None):
    """Pixels of an image file through OpenImageIO: ``(data (H, W, C) with row 0 at the bottom, the file's
    sample format name)``.

    what: the kind of file, for messages; pixel_type(format) -> the type to read as ("float", "uint16",
    "uint8"), raising for formats the caller refuses; n_channels: read only the first ones (None: all).
    """
    oiio, inp = _open(path, what)
    try:
        spec = inp.spec()
        fmt = str(spec.format)
        n = n_channels or spec.nchannels
        data = inp.read_image(0, 0, 0, n, pixel_type(fmt))
        if data is None:
            raise TesseraError(f"Reading {path} failed: {_reason(oiio, inp, 'the file is damaged or truncated')}")
    finally:
        inp.close()
    return np.asarray(data).reshape(spec.height, spec.width, n)[::-1], fmt


def read_channels(path, what, suffixes):
    """Named channels of a float image, across its parts (a multilayer EXR keeps each pass in a part of its own:
    "ViewLayer.Depth.Z", ...): for each suffix, the first channel whose name ends with it, as (H, W) float32 with row
    0 at the bottom. A `TesseraError` naming a missing one."""
    oiio, inp = _open(path, what)
    found = {}
    try:
        part = 0
        while inp.seek_subimage(part, 0):
            spec = inp.spec()
            data = inp.read_image(part, 0, 0, spec.nchannels, "float")
            if data is None:
                raise TesseraError(f"Reading {path} failed: {_reason(oiio, inp, 'the file is damaged or truncated')}")
            data = np.asarray(data).reshape(spec.height, spec.width, spec.nchannels)[::-1]
            for k, name in enumerate(spec.channelnames):
                found.setdefault(name, data[..., k])
            part += 1
    finally:
        inp.close()
    out = []
    for suffix in suffixes:
        name = next((n for n in found if n.endswith(suffix)), None)
        if name is None:
            raise TesseraError(f"{path} has no channel ending in {suffix!r} (it has {', '.join(found)})")
        out.append(np.ascontiguousarray(found[name], np.float32))
    return out


def _reason(oiio, handle, fallback):
    """OpenImageIO's error text (the handle's, then the global one), or ``fallback`` when it gives none."""
    text = ""
    if handle is not None and hasattr(handle, "geterror"):
        text = handle.geterror() or ""
    text = text or oiio.geterror() or ""
    return text.strip() or fallback


def write_pixels(path, rows, fmt, lossless_exr=False):
    """Write ``rows`` (H, W, C), already in file order (top row first), as sample format ``fmt`` ("float",
    "uint16", ...); ``lossless_exr`` sets zip compression. The file appears only when it is complete."""
    h, w, c = rows.shape
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise TesseraError(f"Cannot write {path}: the folder {folder} does not exist")
    oiio = oiio_module()
    spec = oiio.ImageSpec(w, h, c, fmt)
    if lossless_exr:
        spec.attribute("compression", "zip")  # lossless
    stem, ext = os.path.splitext(os.path.basename(path))
    partial = os.path.join(folder, f".{stem}.tessera-partial{ext}")  # same folder: the rename is atomic
    out = oiio.ImageOutput.create(partial)
    try:
        if out is None or not out.open(partial, spec):
            raise TesseraError(f"Cannot write {path}: {_reason(oiio, out, 'the folder may not be writable')}")
        ok = out.write_image(rows)
        closed = out.close()
        if not ok or closed is False:
            raise TesseraError(f"Writing {path} failed: {_reason(oiio, out, 'the disk may be full')}")
        os.replace(partial, path)
    except OSError as err:
        raise TesseraError(f"Cannot write {path}: {err.strerror or err}") from err
    finally:
        if os.path.exists(partial):
            os.remove(partial)

"""The height map the manual's terrain example uses, written anew: ``docs/samples/ridged_height_map.png``, a 513²
16-bit greyscale PNG of `ridged_terrain` (seed 7): a plain on the west, ridged mountains, a plateau. The manual
links it for download and ships it with the extension's copy of the manual. Never edit it by hand: run this.

Usage: python tools/sample_height_map.py [OUT.png]
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ridged_terrain import ridged_terrain  # noqa: E402 -- tools/ is not a package

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "docs" / "samples" / "ridged_height_map.png"
SIZE, SEED = 513, 7


def height_map():
    """(SIZE, SIZE) uint16: the sample's samples, 0 the lowest ground and 65535 the highest."""
    return np.round(ridged_terrain(SIZE, seed=SEED).astype(np.float64) * 65535.0).astype(np.uint16)


def write(path=SAMPLE):
    """Write the sample as a 16-bit greyscale PNG at ``path``."""
    import OpenImageIO as oiio

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    spec = oiio.ImageSpec(SIZE, SIZE, 1, oiio.UINT16)
    out = oiio.ImageOutput.create(str(path))
    if out is None or not out.open(str(path), spec):
        raise RuntimeError(f"could not write {path}: {oiio.geterror()}")
    try:
        if not out.write_image(height_map()[:, :, None]):  # (height, width, channels), top row first
            raise RuntimeError(f"could not write {path}: {out.geterror()}")
    finally:
        out.close()
    return path


if __name__ == "__main__":
    print(write(sys.argv[1] if len(sys.argv) > 1 else SAMPLE))

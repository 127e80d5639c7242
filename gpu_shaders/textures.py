"""Data textures for vertex pulling: rows of RGBA32F texels in a texture `TEX_WIDTH` wide (row-major), read in
GLSL with ``texelFetch(tex, ivec2(i % tex_width, i / tex_width), 0)``; and 2-D images as float textures."""

import numpy as np

TEX_WIDTH = 4096


def rgba_texture(rows):
    """An RGBA32F texture holding ``rows`` (K, 4) float32 texels (zero-padded to whole rows)."""
    import gpu

    height = max(1, -(-len(rows) // TEX_WIDTH))
    data = np.zeros((height * TEX_WIDTH, 4), np.float32)
    data[: len(rows)] = rows
    return gpu.types.GPUTexture((TEX_WIDTH, height), format="RGBA32F",
                                data=gpu.types.Buffer("FLOAT", data.size, data.ravel()))


def image_texture(values, fmt):
    """A float texture of an image: values (H, W) or (H, W, C) with C the channels of ``fmt`` (R32F, RG32F,
    RGBA32F), row 0 at the bottom."""
    import gpu

    v = np.ascontiguousarray(values, np.float32)
    h, w = v.shape[:2]
    return gpu.types.GPUTexture((w, h), format=fmt, data=gpu.types.Buffer("FLOAT", v.size, v.ravel()))

"""Data textures for vertex pulling: rows of RGBA32F texels in a texture `TEX_WIDTH` wide (row-major), read in
GLSL with ``texelFetch(tex, ivec2(i % tex_width, i / tex_width), 0)``; 2-D images as float textures; and what a compute
shader wrote, read back safely (`read_after_compute`)."""

import numpy as np

from . import loader

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


#: The vertex stage of a full-screen pass: one triangle covering the viewport, from the ``corner`` input
#: (`fullscreen_batch`).
FULLSCREEN_VERT = "void main()\n{\n  gl_Position = vec4(corner, 0.0, 1.0);\n}\n"
_COPY_FRAG = "void main()\n{\n  frag_color = texelFetch(source, ivec2(gl_FragCoord.xy), 0);\n}\n"


def _describe_copy():
    import gpu

    info = gpu.types.GPUShaderCreateInfo()
    info.vertex_in(0, "VEC2", "corner")
    info.sampler(0, "FLOAT_2D", "source")
    info.fragment_out(0, "VEC4", "frag_color")
    info.vertex_source(FULLSCREEN_VERT)
    info.fragment_source(_COPY_FRAG)
    return info


def fullscreen_batch(name, shader):
    """The one triangle of a full-screen pass for ``shader`` (its vertex stage `FULLSCREEN_VERT`, input ``corner``),
    cached under ``name``."""
    from gpu_extras.batch import batch_for_shader

    return loader.batch((name,), lambda: batch_for_shader(
        shader, "TRIS", {"corner": np.array([[-1.0, -1.0], [3.0, -1.0], [-1.0, 3.0]], np.float32)}))


def read_after_compute(texture, n):
    """The first ``n`` texels (row-major) of an RGBA32F ``texture`` that a compute shader wrote: (n, 4) float32.

    Read through a draw, not ``GPUTexture.read()``: after ``gpu.compute.dispatch`` Blender orders texture fetches and
    image access, but the Python ``read()`` issues no texture-update barrier (Blender's own C++ callers add one), so
    on a GPU that runs asynchronously it may read the texture before the shader's writes land. A draw that fetches
    every texel into an offscreen framebuffer, and the read of that framebuffer, are ordered by the API itself."""
    import gpu

    w, h = texture.width, texture.height
    shader = loader.shader("texture_copy", _describe_copy)
    batch = fullscreen_batch("texture_copy", shader)
    offscreen = gpu.types.GPUOffScreen(w, h, format="RGBA32F")
    try:
        with offscreen.bind():
            fb = gpu.state.active_framebuffer_get()
            gpu.state.blend_set("NONE")
            gpu.state.depth_test_set("NONE")
            shader.bind()
            shader.uniform_sampler("source", texture)
            batch.draw(shader)
            buf = fb.read_color(0, 0, w, h, 4, 0, "FLOAT")
    finally:
        offscreen.free()
    buf.dimensions = w * h * 4  # multi-dimensional Buffers export wrong strides
    return np.asarray(memoryview(buf), dtype=np.float32).reshape(-1, 4)[:n].copy()

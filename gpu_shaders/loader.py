"""Read GLSL files, build shaders from `GPUShaderCreateInfo` descriptions and pattern batches, once per session.

GLSL follows Blender's cross-compilation rules: no ``#version``, ``layout`` or resource declarations in
the files; inputs, outputs and uniforms are declared in the create-info. Nothing is compiled at import:
`shader` compiles on first use (which needs a GPU context, see `addon.gpu_context`). GLSL files are named by
their path under ``gpu_shaders/`` (``"tubes/tube_vert.glsl"``). `batch` keeps the refinement-pattern batches the
previews draw instanced (`pattern_batch`: as triangles, or as their edges for a wire); `clear` forgets shaders and
batches together.

Every shader is compiled here and nowhere else (`_compile`). A shader that fails is remembered per backend (OpenGL,
Vulkan, Metal) for the session and raised as a `GPUShaderError` naming the backend and the shader, with the start
of the driver's log, every time it is asked for, without compiling it again: a preview stops on it once
(`addon.viewport`), an operator's GPU path falls back to numpy.
"""

from pathlib import Path

import numpy as np

from ..kernels.common.errors import GPUShaderError

GLSL_DIR = Path(__file__).parent
_sources = {}
_shaders = {}
_batches = {}
_failed = {}  # (backend, shader name) -> GPUShaderError
_blocks = {}  # bytes of a uniform buffer -> its GPUUniformBuf (the most recent few)
#: Uniform buffers kept (a frame's draws share one per distinct content; older ones go first).
KEEP_BLOCKS = 64


def source(name):
    """Text of ``gpu_shaders/<name>`` (cached); ``name`` may name a capability folder (``"terrain/..."``)."""
    if name not in _sources:
        _sources[name] = (GLSL_DIR / name).read_text(encoding="utf-8")
    return _sources[name]


def sources(*names):
    """The files ``names`` joined in order (shared functions first), for one shader stage."""
    return "\n".join(source(name) for name in names)


def backend():
    """The GPU backend Blender draws with: "OPENGL", "VULKAN", "METAL" (OpenGL where Blender cannot say)."""
    import gpu

    try:
        return str(gpu.platform.backend_type_get())
    except (AttributeError, RuntimeError):
        return "OPENGL"


def _compile(info):
    """The one place a shader is compiled (from its create-info)."""
    import gpu

    return gpu.shader.create_from_info(info)


def shader(name, describe):
    """Compiled shader ``name``; ``describe()`` returns its `gpu.types.GPUShaderCreateInfo` on first use. Raises
    `GPUShaderError` when it does not compile on this backend (then and on every later call, without compiling it
    again)."""
    if name in _shaders:
        return _shaders[name]
    key = (backend(), name)
    if key in _failed:
        raise _failed[key]
    try:
        _shaders[name] = _compile(describe())
    except Exception as err:  # noqa: BLE001 - Blender raises a bare Exception carrying the compiler's log
        log = " ".join(str(err).split())
        failed = GPUShaderError(f"Tessera's {name!r} shader does not compile on this {key[0].title()} driver "
                                f"({log[:300] or type(err).__name__})")
        _failed[key] = failed
        print(f"Tessera: {failed}")  # once: the failure is remembered
        raise failed from err
    return _shaders[name]


def failures():
    """The shaders that failed to compile this session: {(backend, name): message}."""
    return {key: str(err) for key, err in _failed.items()}


def batch(key, build):
    """The `gpu.types.GPUBatch` cached under ``key`` (a tuple naming the preview and the pattern), made by
    ``build()`` on first use."""
    if key not in _batches:
        _batches[key] = build()
    return _batches[key]


def pattern_batch(key, shader, make, wireframe=False):
    """The `batch` of a refinement pattern drawn instanced, cached under ``key`` and ``wireframe``: ``make()`` gives
    ``(vertex attributes {name: (V, k) array}, triangles (T, 3) int32)`` and optionally the edges (K, 2) int32 the
    applied mesh has (a pattern of quads: not their diagonals); drawn as its triangles, or with ``wireframe`` as those
    edges (by default every edge of the triangles once), as lines."""

    def build():
        from gpu_extras.batch import batch_for_shader

        from ..kernels.common.topology import triangle_edges

        attributes, triangles, *edges = make()
        if wireframe:
            lines = edges[0] if edges else triangle_edges(np.asarray(triangles, np.int32))[0]
            return batch_for_shader(shader, "LINES", attributes, indices=np.asarray(lines, np.int32))
        return batch_for_shader(shader, "TRIS", attributes, indices=np.asarray(triangles, np.int32))

    return batch((*key, "wire" if wireframe else "tris"), build)


def blank_texture():
    """A 1x1 RGBA16F texture (black): bound to a sampler a draw does not read (every declared sampler is bound)."""
    if "blank" not in _batches:
        import gpu

        _batches["blank"] = gpu.types.GPUTexture((1, 1), format="RGBA16F")
    return _batches["blank"]


def block(data):
    """A `gpu.types.GPUUniformBuf` holding ``data`` (float32, a multiple of 16 bytes), one per distinct content
    (never changed after it is made, so a draw never sees another draw's values)."""
    key = bytes(memoryview(data))
    buf = _blocks.pop(key, None)
    if buf is None:
        import gpu

        buf = gpu.types.GPUUniformBuf(data)
    _blocks[key] = buf  # the most recent last
    while len(_blocks) > KEEP_BLOCKS:
        del _blocks[next(iter(_blocks))]
    return buf


def clear():
    """Forget compiled shaders, pattern batches and uniform buffers (their GPU context is gone, e.g. after
    unregister)."""
    _batches.clear()
    _shaders.clear()
    _blocks.clear()

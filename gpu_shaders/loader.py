"""Read GLSL files, build shaders from `GPUShaderCreateInfo` descriptions and pattern batches, once per session.

GLSL follows Blender's cross-compilation rules: no ``#version``, ``layout`` or resource declarations in
the files; inputs, outputs and uniforms are declared in the create-info. Nothing is compiled at import:
`shader` compiles on first use (which needs a GPU context, see `addon.gpu_context`). GLSL files are named by
their path under ``gpu_shaders/`` (``"tubes/tube_vert.glsl"``). `batch` keeps the refinement-pattern batches the
previews draw instanced; `clear` forgets shaders and batches together.
"""

from pathlib import Path

GLSL_DIR = Path(__file__).parent
_sources = {}
_shaders = {}
_batches = {}


def source(name):
    """Text of ``gpu_shaders/<name>`` (cached); ``name`` may name a capability folder (``"terrain/..."``)."""
    if name not in _sources:
        _sources[name] = (GLSL_DIR / name).read_text(encoding="utf-8")
    return _sources[name]


def sources(*names):
    """The files ``names`` joined in order (shared functions first), for one shader stage."""
    return "\n".join(source(name) for name in names)


def shader(name, describe):
    """Compiled shader ``name``; ``describe()`` returns its `gpu.types.GPUShaderCreateInfo` on first use."""
    if name not in _shaders:
        import gpu

        _shaders[name] = gpu.shader.create_from_info(describe())
    return _shaders[name]


def batch(key, build):
    """The `gpu.types.GPUBatch` cached under ``key`` (a tuple naming the preview and the pattern), made by
    ``build()`` on first use."""
    if key not in _batches:
        _batches[key] = build()
    return _batches[key]


def clear():
    """Forget compiled shaders and pattern batches (their GPU context is gone, e.g. after unregister)."""
    _batches.clear()
    _shaders.clear()

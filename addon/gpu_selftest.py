"""The GPU self-test: compile every Tessera shader on the backend Blender runs (OpenGL, Vulkan or Metal) and print
one line per shader, pass or fail with the driver's reason. For a user (a Mac: Metal) or a bug report, the one line in
docs/development.md ("GPU self-test") runs `main` in ``blender -b`` with the installed extension.

Exits with 0 when every shader compiles, 1 otherwise (``main``); `run` returns the results.
"""

import sys

from ..gpu_shaders import catalogue, loader
from ..kernels.common.errors import GPUShaderError
from .gpu_context import ensure_gpu_context


def run():
    """Compile every shader (`gpu_shaders.catalogue`): ``(backend, {name: "" when it compiles, else why})``."""
    renderer = ensure_gpu_context()
    results = {}
    for name, describe in catalogue.describers().items():
        try:
            loader.shader(name, describe)
            results[name] = ""
        except GPUShaderError as err:
            results[name] = str(err)
    return f"{loader.backend()} ({renderer})", results


def main():
    backend, results = run()
    print(f"Tessera GPU self-test on {backend}:")
    for name, why in results.items():
        print(f"  {'PASS' if not why else 'FAIL'}  {name}{'' if not why else ': ' + why}")
    failed = sum(1 for why in results.values() if why)
    print(f"{len(results) - failed} of {len(results)} shaders compile")
    sys.exit(1 if failed else 0)

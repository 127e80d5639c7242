"""Every shader Tessera compiles, by name, with the function that describes it: for the self-test that compiles them
all on the running backend (`addon.gpu_selftest`) and the tests that check each create-info's push constants."""

import importlib

#: (shader name, module under ``gpu_shaders``, the function returning its create-info)
SHADERS = (
    ("flat_mesh", "offscreen", "_describe_flat_mesh"),
    ("nailboard", "impostors.draw", "_describe"),
    ("loop_mesh", "subdivision.draw", "_describe"),
    ("loop_stencils", "subdivision.draw", "_describe_stencils"),
        ("surface_preview", "surfaces.draw", "_describe_preview"),
    ("surface_compute", "surfaces.draw", "_describe_compute"),
    ("tube_preview", "tubes.draw", "_describe"),
    ("patch_preview", "tessellation.draw", "_describe_preview"),
    ("patch_compute", "tessellation.draw", "_describe_compute"),
    ("selection_outline", "outline", "_describe"),
    ("terrain_preview", "terrain.draw", "_describe"),
    ("texture_copy", "textures", "_describe_copy"),
    ("vector_field_advect", "vector_field.streaks", "_describe_advect"),
    ("vector_field_splat", "vector_field.streaks", "_describe_splat"),
)


def describers():
    """{shader name: the function that returns its `gpu.types.GPUShaderCreateInfo`}."""
    out = {}
    for name, module, function in SHADERS:
        out[name] = getattr(importlib.import_module(f"{__package__}.{module}"), function)
    return out

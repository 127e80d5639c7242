"""Vector-field textures on the GPU ([Nellmedin 2014, §5.5.4]): the seed points advected by a compute shader (explicit
Euler, one dispatch a step, ping-pong between two RGBA32F textures) and splatted after every step as one-pixel
points with additive blending into a float offscreen (red: the sum of values, green: how many), the numpy
reference being `kernels.vector_field.streaks` (`advect`, `splat`)."""

import numpy as np

from ...kernels.vector_field.fields import AnalyticField, GridField
from .. import loader
from ..textures import TEX_WIDTH, image_texture, read_after_compute, rgba_texture

FIELD_CODES = {"ABC": 0, "VORTEX": 1}


def _field_constants(info):
    info.push_constant("INT", "field_kind")
    info.push_constant("FLOAT", "slice_z")
    info.push_constant("FLOAT", "speed")
    info.push_constant("IVEC2", "grid_size")
    info.push_constant("INT", "tex_width")


def _describe_advect():
    import gpu

    info = gpu.types.GPUShaderCreateInfo()
    _field_constants(info)
    info.push_constant("FLOAT", "step_size")
    info.push_constant("INT", "count")
    info.sampler(0, "FLOAT_2D", "points_in")
    info.sampler(1, "FLOAT_2D", "grid")
    info.image(0, "RGBA32F", "FLOAT_2D", "points_out", qualifiers={"WRITE"})
    info.local_group_size(64, 1, 1)
    info.compute_source(loader.sources("vector_field/field.glsl", "vector_field/advect_comp.glsl"))
    return info


def _describe_splat():
    import gpu

    iface = gpu.types.GPUStageInterfaceInfo("tessera_streak_iface")
    iface.flat("FLOAT", "value")
    info = gpu.types.GPUShaderCreateInfo()
    info.push_constant("INT", "tex_width")
    info.sampler(0, "FLOAT_2D", "points")
    info.vertex_in(0, "FLOAT", "id")
    info.vertex_out(iface)
    info.fragment_out(0, "VEC4", "frag_color")
    info.vertex_source(loader.source("vector_field/splat_vert.glsl"))
    info.fragment_source(loader.source("vector_field/splat_frag.glsl"))
    return info


def _set_field(shader, field, grid_texture):
    if isinstance(field, AnalyticField):
        shader.uniform_int("field_kind", FIELD_CODES[field.kind])
        shader.uniform_float("slice_z", float(field.slice_z))
        shader.uniform_float("speed", float(field.speed))
        shader.uniform_int("grid_size", (2, 2))
    else:
        shader.uniform_int("field_kind", 2)
        shader.uniform_float("slice_z", 0.0)
        shader.uniform_float("speed", 1.0)
        h, w = np.asarray(field.values).shape[:2]
        shader.uniform_int("grid_size", (w, h))
    shader.uniform_sampler("grid", grid_texture)


def _grid_texture(field):
    import gpu

    if isinstance(field, GridField):
        v = np.asarray(field.values, np.float32)
        h, w = v.shape[:2]
        rgba = np.zeros((h, w, 4), np.float32)
        rgba[..., :2] = v
        return image_texture(rgba, "RGBA32F")
    return gpu.types.GPUTexture((2, 2), format="RGBA32F")


def _read_points(texture, n):
    return read_after_compute(texture, n)


def streak_shaders():
    """The advection and splat shaders of `streaks_on_gpu`, compiled (a `GPUShaderError` when this backend cannot)."""
    return loader.shader("vector_field_advect", _describe_advect), loader.shader("vector_field_splat", _describe_splat)


def streaks_on_gpu(field, points, values, width, height, step, steps, keep_points=False):
    """The texture of `kernels.vector_field.streaks.streak_image`'s splats, on the GPU: ``(total (H, W), count
    (H, W))`` float32 sums and counts, and with ``keep_points`` the points after the last step (N, 2). points (N, 2),
    values (N,). Needs a GPU context."""
    import gpu
    from gpu_extras.batch import batch_for_shader

    n = len(points)
    rows = np.zeros((n, 4), np.float32)
    rows[:, :2], rows[:, 2] = points, values
    tex_h = max(1, -(-n // TEX_WIDTH))
    ping = rgba_texture(rows)
    pong = gpu.types.GPUTexture((TEX_WIDTH, tex_h), format="RGBA32F")
    grid = _grid_texture(field)
    advect, splat = streak_shaders()
    batch = batch_for_shader(splat, "POINTS", {"id": np.arange(n, dtype=np.float32)})
    offscreen = gpu.types.GPUOffScreen(width, height, format="RGBA32F")
    try:
        with offscreen.bind():
            fb = gpu.state.active_framebuffer_get()
            fb.clear(color=(0.0, 0.0, 0.0, 0.0))
            gpu.state.blend_set("ADDITIVE")
            gpu.state.depth_test_set("NONE")

            def draw_points(points_texture):
                splat.bind()
                splat.uniform_int("tex_width", TEX_WIDTH)
                splat.uniform_sampler("points", points_texture)
                batch.draw(splat)

            draw_points(ping)  # the seeds themselves, as the trajectory's first row
            for _ in range(int(steps)):
                advect.bind()
                _set_field(advect, field, grid)
                advect.uniform_int("tex_width", TEX_WIDTH)
                advect.uniform_float("step_size", float(step))
                advect.uniform_int("count", n)
                advect.uniform_sampler("points_in", ping)
                advect.image("points_out", pong)
                gpu.compute.dispatch(advect, TEX_WIDTH // 64, tex_h, 1)
                ping, pong = pong, ping
                draw_points(ping)
            buf = fb.read_color(0, 0, width, height, 4, 0, "FLOAT")
            gpu.state.blend_set("NONE")
    finally:
        offscreen.free()
    buf.dimensions = width * height * 4
    image = np.asarray(memoryview(buf), dtype=np.float32).reshape(height, width, 4)
    result = (image[..., 0].copy(), image[..., 1].copy())
    if keep_points:
        return result + (_read_points(ping, n)[:, :2],)
    return result

"""One-point parametric surfaces drawn on the GPU ([Nunes 2011, §2.3–2.4]), with no mesh uploaded.

The factor-F quad-domain pattern (`kernels.surfaces.domain_mesh.domain_pattern`: (F + 1)² domain coordinates and
2F² triangles) is one batch, shared by every surface and instance. The control points are one RGBA32F texture
(16 bytes a point); `SurfaceDrawData.draw` draws the pattern instanced, one instance per control point, and the
vertex shader (``surface_vert.glsl``) evaluates the surface's formula (``surface_eval.glsl``) at each pattern vertex.
Instances may have different factors (from the camera, `kernels.surfaces.domain_mesh.camera_factors`): one draw
per factor, over the instances sorted by factor. `evaluate_on_gpu` runs the same formula in a compute shader and
reads the vertices back, so tests compare the drawn vertices with the numpy kernel.
"""

import numpy as np

from ...kernels.surfaces.domain_mesh import domain_pattern
from ...kernels.surfaces.parametric import SURFACES
from .. import loader
from ..offscreen import set_shading, shaded_create_info
from ..textures import TEX_WIDTH, read_after_compute, rgba_texture

KINDS = {cls: i for i, cls in enumerate(SURFACES.values())}


def shape_vector(surface):
    """A surface's kind code (its index in `SURFACES`) and its shape parameters as a vec4 (field order)."""
    import dataclasses

    values = [float(getattr(surface, f.name)) for f in dataclasses.fields(surface)]
    return KINDS[type(surface)], tuple(values + [0.0] * (4 - len(values)))


def _constants(info):
    info.push_constant("INT", "kind")
    info.push_constant("VEC4", "shape")
    info.push_constant("INT", "tex_width")
    info.sampler(0, "FLOAT_2D", "control_points")


def _describe_preview():
    info = shaded_create_info("surface", "surfaces/surface_eval.glsl", "surfaces/surface_vert.glsl")
    _constants(info)
    info.push_constant("INT", "first_instance")
    info.vertex_in(0, "VEC2", "uv")
    return info


def _describe_compute():
    import gpu

    info = gpu.types.GPUShaderCreateInfo()
    _constants(info)
    info.push_constant("INT", "factor")
    info.push_constant("INT", "domain_count")
    info.push_constant("INT", "instance_count")
    info.image(0, "RGBA32F", "FLOAT_2D", "out_positions", qualifiers={"WRITE"})
    info.local_group_size(64, 1, 1)
    info.compute_source(loader.sources("surfaces/surface_eval.glsl", "surfaces/surface_comp.glsl"))
    return info


def pattern_bytes(factor):
    """Bytes the factor-F pattern batch uploads: (F + 1)² vec2 coordinates and 2F² x 3 int32 indices."""
    uv, tris = domain_pattern(factor)
    return uv.nbytes + tris.nbytes


def _pattern_batch(shader, factor, wireframe=False):
    def make():
        uv, tris = domain_pattern(factor)
        return {"uv": uv}, tris

    return loader.pattern_batch(("surfaces", factor), shader, make, wireframe)


class SurfaceDrawData:
    """GPU resources of N instances of one surface: the control-point texture (uploaded once) and, per factor,
    the range of instances drawn with it.

    surface: a `kernels.surfaces.parametric` surface; control_points: (N, 3); factors: one int F for all, or
    (N,) ints per instance (1 .. 64)."""

    def __init__(self, surface, control_points, factors):
        points = np.asarray(control_points, np.float32).reshape(-1, 3)
        f = np.broadcast_to(np.asarray(factors, np.int64), (len(points),))
        order = np.argsort(f, kind="stable")
        rows = np.zeros((len(points), 4), np.float32)
        rows[:, :3] = points[order]
        self.kind, self.shape = shape_vector(surface)
        self.texture = rgba_texture(rows)
        self.control_bytes = rows.nbytes
        sorted_f = f[order]
        starts = np.flatnonzero(np.r_[True, sorted_f[1:] != sorted_f[:-1]]) if len(f) else np.zeros(0, np.int64)
        ends = np.r_[starts[1:], len(f)]
        self.ranges = [(int(sorted_f[s]), int(s), int(e - s)) for s, e in zip(starts, ends, strict=True)]

    @property
    def triangle_count(self):
        return sum(2 * factor * factor * count for factor, _, count in self.ranges)

    @property
    def uploaded_bytes(self):
        """Control points plus each factor's pattern batch (shared by every surface drawn at that factor)."""
        return self.control_bytes + sum(pattern_bytes(factor) for factor, _, _ in self.ranges)

    def draw(self, view_projection, color=(0.8, 0.8, 0.8, 1.0), lit=True, wireframe=False, lighting=None):
        """Draw into the bound framebuffer; view_projection: (4, 4) row-major, object space to clip space; lighting:
        an `offscreen.ViewLighting` to light as the viewport does, or None for the check shade."""
        shader = loader.shader("surface_preview", _describe_preview)
        set_shading(shader, view_projection, color, lit, lighting)
        shader.uniform_int("kind", self.kind)
        shader.uniform_float("shape", self.shape)
        shader.uniform_int("tex_width", TEX_WIDTH)
        shader.uniform_sampler("control_points", self.texture)
        for factor, first, count in self.ranges:
            shader.uniform_int("first_instance", first)
            _pattern_batch(shader, factor, wireframe).draw_instanced(shader, instance_start=0, instance_count=count)


def evaluate_on_gpu(surface, control_points, factor):
    """Every domain vertex of every instance as the preview places it, by the compute shader: (N * (F + 1)², 3)
    float32, instance-major (the order of `kernels.surfaces.domain_mesh.instance_positions`). Needs a GPU
    context."""
    import gpu

    points = np.asarray(control_points, np.float32).reshape(-1, 3)
    rows = np.zeros((len(points), 4), np.float32)
    rows[:, :3] = points
    n_domain = (factor + 1) ** 2
    n = len(points) * n_domain
    height = max(1, -(-n // TEX_WIDTH))
    out = gpu.types.GPUTexture((TEX_WIDTH, height), format="RGBA32F")
    shader = loader.shader("surface_compute", _describe_compute)
    shader.bind()
    kind, shape = shape_vector(surface)
    shader.uniform_int("kind", kind)
    shader.uniform_float("shape", shape)
    shader.uniform_int("tex_width", TEX_WIDTH)
    shader.uniform_int("factor", int(factor))
    shader.uniform_int("domain_count", n_domain)
    shader.uniform_int("instance_count", len(points))
    control = rgba_texture(rows)  # held until the dispatch: a freed texture reads as zeros
    shader.uniform_sampler("control_points", control)
    shader.image("out_positions", out)
    gpu.compute.dispatch(shader, TEX_WIDTH // 64, height, 1)
    return read_after_compute(out, n)[:, :3].copy()

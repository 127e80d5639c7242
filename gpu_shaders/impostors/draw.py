"""A nailboard on the GPU ([Clua et al., §4.1]): the board is one quad on its plane; the
fragment shader reads the offset map (the CPU pre-warp, `kernels.impostors.prewarp.forward_splat`) at its texel,
fetches the source texel's colour (a dependent lookup, nearest) and writes the depth of that texel's relief point,
so the board composites per texel with the rest of the scene (it intersects and occludes as the object would)."""

import numpy as np

from .. import loader
from ..offscreen import add_view_block, view_block
from ..textures import image_texture


def _describe():
    import gpu

    iface = gpu.types.GPUStageInterfaceInfo("tessera_board_iface")
    iface.smooth("VEC2", "texel")
    info = gpu.types.GPUShaderCreateInfo()
    add_view_block(info)
    info.push_constant("VEC3", "origin")
    info.push_constant("VEC3", "axis_a")
    info.push_constant("VEC3", "axis_b")
    info.push_constant("VEC3", "normal_f")
    info.push_constant("INT", "lit")
    info.sampler(0, "FLOAT_2D", "offsets")
    info.sampler(1, "FLOAT_2D", "colours")
    info.sampler(2, "FLOAT_2D", "displacement")
    info.sampler(3, "FLOAT_2D", "normals")
    info.vertex_in(0, "VEC2", "corner")
    info.vertex_out(iface)
    info.fragment_out(0, "VEC4", "frag_color")
    if hasattr(info, "depth_write"):  # 4.5+ declares it; 4.2's OpenGL takes gl_FragDepth as it is
        info.depth_write("ANY")
    info.vertex_source(loader.source("impostors/board_vert.glsl"))
    info.fragment_source(loader.source("impostors/board_frag.glsl"))
    return info


def offset_rows(splat):
    """The offset map of a `Splat` as the GPU takes it: (H, W, 2) float32 source texel centres, holes (NaN) as -1,
    an address no texel has (the shader tests for it: no NaN comparison on the GPU). Pure numpy: a worker thread
    makes it with the pre-warp, so the draw only uploads."""
    return np.nan_to_num(np.asarray(splat.offsets, np.float32), nan=-1.0)


class BoardDrawData:
    """GPU resources of one nailboard: frame (`kernels.impostors.prewarp.ReliefFrame`); colours (H, W, 4),
    displacement (H, W) and normals (H, W, 3) of its source images; splat: the `Splat` of the current pre-warp."""

    def __init__(self, frame, colours, displacement, splat, normals=None, rows=None):
        for _ in self._steps(frame, colours, displacement, splat, normals, rows):
            pass

    @classmethod
    def steps(cls, frame, colours, displacement, splat, normals=None, rows=None):
        """The same, made one upload at a time (a generator returning the `BoardDrawData`; its shader compiled
        first): a viewport that takes one step per redraw is never held by all of them at once."""
        data = cls.__new__(cls)
        yield from data._steps(frame, colours, displacement, splat, normals, rows)
        return data

    def _steps(self, frame, colours, displacement, splat, normals, rows):
        h, w = np.asarray(displacement).shape
        self.frame, self.size = frame, (w, h)
        loader.shader("nailboard", _describe)
        yield
        self.colours = image_texture(colours, "RGBA32F")
        yield
        self.displacement = image_texture(displacement, "R32F")
        yield
        n = np.zeros((h, w, 4), np.float32)
        if normals is not None:
            n[..., :3] = normals
        self.normals = image_texture(n, "RGBA32F")
        yield
        self.set_splat(splat, rows)

    def set_splat(self, splat, rows=None):
        """Upload a new offset map (a new pre-warp for a moved eye): 8 bytes a texel; rows: its `offset_rows` when
        made already (on a worker thread)."""
        self.splat = splat
        self.offsets = image_texture(offset_rows(splat) if rows is None else rows, "RG32F")

    def draw(self, view_projection, lit=False, light_dir=(0.3, -0.5, 0.81), mask_color=None):
        """Draw into the bound framebuffer (depth test as the caller set it); view_projection (4, 4) row-major;
        mask_color: rgba every texel of the board is drawn in instead of its colour (a selection outline's mask)."""
        from gpu_extras.batch import batch_for_shader

        shader = loader.shader("nailboard", _describe)
        w, h = self.size

        def build():
            corners = np.array([[0, 0], [w, 0], [w, h], [0, h]], np.float32)
            return batch_for_shader(shader, "TRIS", {"corner": corners},
                                    indices=np.array([[0, 1, 2], [0, 2, 3]], np.int32))

        batch = loader.batch(("nailboard", w, h), build)
        shader.bind()
        shader.uniform_block("shading", view_block(view_projection, color=tuple(mask_color or (1.0, 1.0, 1.0, 1.0)),
                                                   light_dir=tuple(light_dir)))
        f = self.frame
        for name, value in (("origin", f.origin), ("axis_a", f.a), ("axis_b", f.b), ("normal_f", f.f)):
            shader.uniform_float(name, tuple(float(x) for x in value))
        shader.uniform_int("lit", 2 if mask_color is not None else 1 if lit else 0)
        shader.uniform_sampler("offsets", self.offsets)
        shader.uniform_sampler("colours", self.colours)
        shader.uniform_sampler("displacement", self.displacement)
        shader.uniform_sampler("normals", self.normals)
        batch.draw(shader)

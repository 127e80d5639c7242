"""A Loop-subdivided mesh on the GPU: positions, normals and colours per vertex and the triangles, uploaded once
per result (`LoopDrawData`); drawn as every preview is (`offscreen.shaded_create_info`): lit as Solid mode lights
objects, the base colour either the object's or the vertex colours (the baked light, as Solid mode's Color:
Attribute shows the applied result's colours), or drawn as they are (the check shade with ``lit=False``)."""

import numpy as np

from ...kernels.common.topology import triangle_edges
from .. import loader
from ..offscreen import set_shading, shaded_create_info

CLAY = (0.72, 0.72, 0.72, 1.0)


def _describe():
    info = shaded_create_info("loop_mesh", "subdivision/loop_vert.glsl", vertex_color=True)
    info.vertex_in(0, "VEC3", "pos")
    info.vertex_in(1, "VEC3", "nor")
    info.vertex_in(2, "VEC4", "col")
    return info


class LoopDrawData:
    """positions (V, 3), normals (V, 3) float32 in object space, colours (V, 4) or None (clay), triangles (F, 3)
    int32. ``triangles`` is kept (tests compare it); the batch is made on the first draw (needs a GPU context)."""

    def __init__(self, positions, normals, colours, triangles):
        self.positions = np.ascontiguousarray(positions, np.float32)
        self.normals = np.ascontiguousarray(normals, np.float32)
        self.baked = colours is not None
        self.colours = np.ascontiguousarray(
            np.broadcast_to(np.float32(CLAY), (len(self.positions), 4)) if colours is None else colours, np.float32)
        self.triangles = np.ascontiguousarray(triangles, np.int32)
        self._batch = self._wire = None

    def draw(self, view_projection, color=CLAY, lit=None, lighting=None, vertex_colors=None, wireframe=False):
        """Draw into the bound framebuffer; view_projection: (4, 4) row-major, object space to clip. lit: shade
        (default: only without baked colours, which carry their own light); lighting: an `offscreen.ViewLighting`
        to light as the viewport does, or None for the check shade; vertex_colors: the base colour is the vertex
        colours (default: when baked), else ``color``; wireframe: the edges in ``color``, unlit."""
        from gpu_extras.batch import batch_for_shader

        shader = loader.shader("loop_mesh", _describe)
        if self._batch is None:
            self._batch = batch_for_shader(shader, "TRIS", {"pos": self.positions, "nor": self.normals,
                                                            "col": self.colours}, indices=self.triangles)
        if wireframe:
            if self._wire is None:
                self._wire = batch_for_shader(shader, "LINES", {"pos": self.positions, "nor": self.normals,
                                                                "col": self.colours},
                                              indices=triangle_edges(self.triangles)[0])
            set_shading(shader, view_projection, color, False)
            self._wire.draw(shader)
            return
        lit = not self.baked if lit is None else lit
        vertex_colors = self.baked if vertex_colors is None else vertex_colors
        set_shading(shader, view_projection, color, lit, lighting, vertex_colors)
        self._batch.draw(shader)


def _describe_stencils():
    import gpu

    info = gpu.types.GPUShaderCreateInfo()
    for name in ("tex_width", "face_count", "rows", "width_p"):
        info.push_constant("INT", name)
    for slot, name in enumerate(("points", "patch_ids", "outputs", "stencil", "weights")):
        info.sampler(slot, "FLOAT_2D", name)
    info.image(0, "RGBA32F", "FLOAT_2D", "out_positions", qualifiers={"WRITE"})
    info.local_group_size(64, 1, 1)
    info.compute_source(loader.source("subdivision/loop_stencil_comp.glsl"))
    return info


def _scalars(values):
    """Scalars (N,) as an RGBA32F texture, four to a texel."""
    from ..textures import rgba_texture

    flat = np.asarray(values, np.float32).ravel()
    padded = np.zeros(-(-max(len(flat), 1) // 4) * 4, np.float32)
    padded[: len(flat)] = flat
    return rgba_texture(padded.reshape(-1, 4))


def evaluate_stencils_on_gpu(table, positions):
    """Loop-subdivided positions (V_L, 3) float32 from a `kernels.subdivision.loop_stencils.StencilTable` and the
    coarse positions (V, 3), by the compute shader: one invocation per coarse triangle. Needs a GPU context."""
    import gpu

    from ..textures import TEX_WIDTH, read_after_compute, rgba_texture

    if table.n_vertices >= 2**24 or len(positions) >= 2**24:
        raise ValueError("the GPU stencil path keeps ids as exact float32: at most 16.7M vertices")
    pts = np.zeros((len(positions), 4), np.float32)
    pts[:, :3] = positions
    n_f, width_p = table.patch.shape
    rows = table.outputs.shape[1]
    height = max(1, -(-table.n_vertices // TEX_WIDTH))
    out = gpu.types.GPUTexture((TEX_WIDTH, height), format="RGBA32F")
    shader = loader.shader("loop_stencils", _describe_stencils)
    shader.bind()
    for name, value in (("tex_width", TEX_WIDTH), ("face_count", n_f), ("rows", rows), ("width_p", width_p)):
        shader.uniform_int(name, value)
    textures = {"points": rgba_texture(pts), "patch_ids": _scalars(table.patch), "outputs": _scalars(table.outputs),
                "stencil": _scalars(table.stencil), "weights": _scalars(table.weights)}
    for name, tex in textures.items():
        shader.uniform_sampler(name, tex)
    shader.image("out_positions", out)
    gpu.compute.dispatch(shader, -(-n_f // 64), 1, 1)
    return read_after_compute(out, table.n_vertices)[:, :3].copy()

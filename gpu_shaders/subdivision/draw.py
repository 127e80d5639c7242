"""A Loop-subdivided mesh on the GPU: positions, normals and colours per vertex and the triangles, uploaded once
per result (`LoopDrawData`); drawn with a headlight in the viewport's view, the colours as they are (baked light)
when ``lit_range`` is (1, 0)."""

import numpy as np

from .. import loader
from ..offscreen import add_view_block, view_block

CLAY = (0.72, 0.72, 0.72, 1.0)


def _describe():
    import gpu

    iface = gpu.types.GPUStageInterfaceInfo("tessera_loop_iface")
    iface.smooth("FLOAT", "shade")
    iface.smooth("VEC4", "vertex_color")
    info = gpu.types.GPUShaderCreateInfo()
    add_view_block(info)
    info.push_constant("MAT4", "model_view")
    info.vertex_in(0, "VEC3", "pos")
    info.vertex_in(1, "VEC3", "nor")
    info.vertex_in(2, "VEC4", "col")
    info.vertex_out(iface)
    info.fragment_out(0, "VEC4", "frag_color")
    info.vertex_source(loader.source("subdivision/loop_vert.glsl"))
    info.fragment_source(loader.source("subdivision/loop_frag.glsl"))
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
        self._batch = None

    def draw(self, model_view, projection, lit=None):
        """Draw with ``model_view`` and ``projection`` (4, 4) row-major; lit: shade by the headlight (default: only
        without baked colours, which carry their own light)."""
        from gpu_extras.batch import batch_for_shader

        shader = loader.shader("loop_mesh", _describe)
        if self._batch is None:
            self._batch = batch_for_shader(shader, "TRIS", {"pos": self.positions, "nor": self.normals,
                                                            "col": self.colours}, indices=self.triangles)
        lit = not self.baked if lit is None else lit
        shader.bind()
        mvp = np.asarray(projection, np.float32) @ np.asarray(model_view, np.float32)
        shader.uniform_block("shading", view_block(mvp, lit_range=(0.3, 0.7) if lit else (1.0, 0.0)))
        shader.uniform_float("model_view", np.asarray(model_view, np.float32).T.ravel().tolist())
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

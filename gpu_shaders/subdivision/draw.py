"""A Loop-subdivided mesh on the GPU: positions, normals and colours per vertex and the triangles, uploaded once
per result (`LoopDrawData`); drawn with a headlight in the viewport's view, the colours as they are (baked light)
when ``lit_range`` is (1, 0)."""

import numpy as np

from .. import loader

CLAY = (0.72, 0.72, 0.72, 1.0)


def _describe():
    import gpu

    iface = gpu.types.GPUStageInterfaceInfo("tessera_loop_iface")
    iface.smooth("FLOAT", "shade")
    iface.smooth("VEC4", "vertex_color")
    info = gpu.types.GPUShaderCreateInfo()
    info.push_constant("MAT4", "model_view_projection")
    info.push_constant("MAT4", "model_view")
    info.push_constant("VEC2", "lit_range")
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
        shader.uniform_float("model_view_projection", mvp.T.ravel().tolist())
        shader.uniform_float("model_view", np.asarray(model_view, np.float32).T.ravel().tolist())
        shader.uniform_float("lit_range", (0.3, 0.7) if lit else (1.0, 0.0))
        self._batch.draw(shader)

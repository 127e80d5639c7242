"""Terrain drawn on the GPU from its height map ([Nunes 2011, §5.6]): no terrain mesh is uploaded.

The height map goes up once as an R32F texture (at most `MAX_TEXTURE` texels a side: larger maps are
strided for the preview). Per view, `TerrainDrawData.set_selection` uploads 48 bytes per visible tile (its
rectangle, edge levels and inner levels along x and y) into one texture per pattern class; each class's pattern
(`kernels.terrain.mesh`) is drawn instanced, one instance per tile, and the vertex shader places and displaces its
vertices with the same partition as the numpy bake, so shared edges produce the same vertices from both tiles.
"""

import numpy as np

from ...kernels.common.partition import clamp_levels
from ...kernels.terrain.analysis import tile_bounds
from ...kernels.terrain.mesh import pattern, pattern_classes, pattern_codes
from .. import loader
from ..offscreen import set_shading, shaded_create_info
from ..textures import TEX_WIDTH, image_texture, rgba_texture

MAX_TEXTURE = 8192


def _describe():
    info = shaded_create_info("terrain", "partition.glsl", "terrain/terrain_vert.glsl")
    info.push_constant("VEC4", "edge_counts")
    info.push_constant("VEC2", "inner_counts")
    info.push_constant("VEC4", "grid")
    info.push_constant("FLOAT", "height_stride")
    info.push_constant("INT", "tex_width")
    info.push_constant("INT", "fractional")
    info.sampler(0, "FLOAT_2D", "tiles")
    info.sampler(1, "FLOAT_2D", "heights")
    info.vertex_in(0, "VEC3", "code")
    return info


def _pattern_batch(shader, key, wireframe=False):
    """The tile pattern of class ``key`` (cached), its triangles or its edges."""
    return loader.pattern_batch(("terrain", key), shader, lambda: ({"code": pattern_codes(*key)}, pattern(*key)),
                                wireframe)


class TerrainDrawData:
    """GPU resources of one terrain: the height texture, and per-class tile textures for the current view."""

    def __init__(self, hm, table):
        self.hm, self.table = hm, table
        self.stride = max(1, -(-max(hm.width, hm.height) // MAX_TEXTURE))
        rows = np.arange(0, hm.height, self.stride)
        heights = np.ascontiguousarray(np.concatenate([hm.rows(int(r), int(r) + 1) for r in rows])[:, ::self.stride])
        self.heights = image_texture(heights, "R32F")
        self.height_bytes = heights.nbytes
        self.buckets, self.tile_bytes, self.fractional = {}, 0, False
        ntx, nty = table.counts
        xb, yb = tile_bounds(np.arange(ntx), table.tile_size, hm.width), tile_bounds(np.arange(nty), table.tile_size,
                                                                                     hm.height)
        rect = np.zeros((nty, ntx, 4), np.float32)
        rect[..., 0], rect[..., 2] = xb[0][None, :], xb[1][None, :]
        rect[..., 1], rect[..., 3] = yb[0][:, None], yb[1][:, None]
        self.rects = rect.reshape(-1, 4)

    def set_selection(self, selection):
        """Upload the tiles of each pattern class for a new `terrain_lod.Selection`."""
        sp = selection.spacing
        h, v = clamp_levels(selection.h_edges, sp), clamp_levels(selection.v_edges, sp)
        levels = np.stack([h[:-1], v[:, 1:], h[1:], v[:, :-1]], -1).reshape(-1, 4).astype(np.float32)
        inner = np.stack([clamp_levels(level, sp).ravel() for level in selection.inner_levels], -1).astype(np.float32)
        self.fractional = sp == "FRACTIONAL_EVEN"
        self.buckets, self.tile_bytes = {}, 0
        for key, tiles in pattern_classes(selection).items():
            rows = np.zeros((len(tiles), 3, 4), np.float32)
            rows[:, 0], rows[:, 1], rows[:, 2, :2] = self.rects[tiles], levels[tiles], inner[tiles]
            self.buckets[key] = (rgba_texture(rows.reshape(-1, 4)), len(tiles))
            self.tile_bytes += rows.nbytes

    def draw(self, view_projection, color=(0.8, 0.8, 0.8, 1.0), lit=True, lighting=None, wireframe=False):
        """Draw into the bound framebuffer. view_projection: (4, 4) row-major, terrain-local space to clip;
        lighting: an `offscreen.ViewLighting` to light as the viewport does, or None for the check shade;
        wireframe: the edges of the tiles' triangles instead."""
        shader = loader.shader("terrain_preview", _describe)
        set_shading(shader, view_projection, color, lit, lighting)
        hm = self.hm
        shader.uniform_float("grid", ((hm.width - 1) * 0.5, (hm.height - 1) * 0.5, *hm.texel))
        shader.uniform_float("height_stride", float(self.stride))
        shader.uniform_int("tex_width", TEX_WIDTH)
        shader.uniform_int("fractional", 1 if self.fractional else 0)
        shader.uniform_sampler("heights", self.heights)
        for key, (texture, count) in self.buckets.items():
            shader.uniform_float("edge_counts", tuple(float(c) for c in key[:4]))
            shader.uniform_float("inner_counts", (float(key[4]), float(key[5])))
            shader.uniform_sampler("tiles", texture)
            _pattern_batch(shader, key, wireframe).draw_instanced(shader, instance_start=0, instance_count=count)

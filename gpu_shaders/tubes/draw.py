"""Tubes drawn on the GPU from section data ([Nunes 2011, §4.4] and §4.6): no tube mesh is uploaded.

`TubeDrawData` turns polylines plus their frames into two kinds of RGBA32F textures: the sections (centre,
radius, N, B: 48 bytes per point, uploaded when the curves change) and, per side count, a patch table (16
bytes per patch of up to 63 segments, uploaded when the level of detail changes). One pattern batch per side
count (64 sections x n sides, welded around) is drawn instanced, one instance per patch; consecutive patches
share their boundary section, so the tube is watertight. The vertex shader applies the anti-aliasing clamp.
"""

import numpy as np

from .. import loader
from ..offscreen import set_shading, shaded_create_info
from ..textures import TEX_WIDTH, rgba_texture

SECTIONS_PER_PATCH = 64  # 63 segments; the last section is the next patch's first


def _describe():
    info = shaded_create_info("tube", "tubes/tube_vert.glsl")
    info.push_constant("MAT4", "inverse_view_projection")
    info.push_constant("VEC2", "clamp_radius")
    info.push_constant("FLOAT", "sides")
    info.push_constant("FLOAT", "viewport_width")
    info.push_constant("INT", "tex_width")
    info.sampler(0, "FLOAT_2D", "sections")
    info.sampler(1, "FLOAT_2D", "patches")
    info.vertex_in(0, "VEC2", "ij")
    return info


def section_table(lines, normals, binormals, radius):
    """(P * 3, 4) float32 texel rows: (centre, radius), (N, 0), (B, 0) per point."""
    out = np.zeros((len(lines.points), 3, 4), np.float32)
    out[:, 0, :3] = lines.points
    out[:, 0, 3] = radius
    out[:, 1, :3] = normals
    out[:, 2, :3] = binormals
    return out.reshape(-1, 4)


def patch_table(lines):
    """Patches (K, 2) int64 of (first section, segments <= 63) covering every segment of every curve.

    A cyclic curve's closing segment needs its first section again after the last: `section_order` lists the
    sections in drawing order with those repeats; patch entries index that order.
    """
    counts = lines.counts
    segs = counts - 1 + lines.cyclic
    order_counts = segs + 1  # sections per curve in drawing order (cyclic: first repeated at the end)
    order_off = np.concatenate(([0], np.cumsum(order_counts)))
    per_curve = np.maximum(0, (segs + SECTIONS_PER_PATCH - 2) // (SECTIONS_PER_PATCH - 1))
    curve = np.repeat(np.arange(lines.n_curves), per_curve)
    local = np.arange(len(curve)) - np.repeat(np.concatenate(([0], np.cumsum(per_curve)))[:-1], per_curve)
    first = order_off[curve] + local * (SECTIONS_PER_PATCH - 1)
    length = np.minimum(SECTIONS_PER_PATCH - 1, segs[curve] - local * (SECTIONS_PER_PATCH - 1))
    return np.stack((first, length), axis=1), curve


def section_order(lines):
    """Point index of every section in drawing order (cyclic curves repeat their first point): (S,) int64."""
    idx = np.arange(len(lines.points))
    closing = lines.cyclic & (lines.counts > 0)
    extra = lines.offsets[:-1][closing]
    where = lines.offsets[1:][closing]  # insert after each cyclic curve's last point
    return np.insert(idx, where, extra)


def ring_pattern(n):
    """The ring pattern with ``n`` sides: vertex attributes {"ij": (64 n, 2) float32: section and side}, its 63 x n
    quads as triangles (126 n, 3) int32, and the quads' edges (127 n, 2) int32: each section's ring and the lines from
    one section to the next, as the tube mesh has them (no diagonals)."""
    k, j = np.meshgrid(np.arange(SECTIONS_PER_PATCH), np.arange(n), indexing="ij")
    ij = np.stack((k, j), axis=-1).reshape(-1, 2).astype(np.float32)
    a = (np.arange(SECTIONS_PER_PATCH - 1)[:, None] * n + np.arange(n)[None, :]).ravel()
    a1 = (np.arange(SECTIONS_PER_PATCH - 1)[:, None] * n + (np.arange(n)[None, :] + 1) % n).ravel()
    tris = np.concatenate((np.stack((a, a1, a1 + n), 1), np.stack((a, a1 + n, a + n), 1))).astype(np.int32)
    every = np.arange(SECTIONS_PER_PATCH * n)
    rings = np.stack((every, every - every % n + (every + 1) % n), 1)
    along = np.stack((a, a + n), 1)
    return {"ij": ij}, tris, np.concatenate((rings, along)).astype(np.int32)


def pattern_batch(shader, n, wireframe=False):
    """Instanced `ring_pattern` with ``n`` sides: its triangles, or with ``wireframe`` its quads' edges (cached)."""
    return loader.pattern_batch(("tubes", n), shader, lambda: ring_pattern(n), wireframe)


class TubeDrawData:
    """GPU resources for one set of tubes; `upload_sections` when the curves change, `set_sides` when the LOD does."""

    def __init__(self, lines, normals, binormals, radius):
        self.lines = lines
        order = section_order(lines)
        self.sections = rgba_texture(section_table(lines, normals, binormals, radius)[
            (3 * order[:, None] + np.arange(3)).ravel()])
        self.section_bytes = len(order) * 48
        self.patches, self.patch_curve = patch_table(lines)
        self.buckets = {}
        self.patch_bytes = 0

    def set_sides(self, sides):
        """Per-curve side counts (C,) -> one patch texture per distinct count."""
        per_patch = np.asarray(sides)[self.patch_curve]
        self.buckets = {}
        self.patch_bytes = 0
        for n in np.unique(per_patch):
            rows = np.zeros((int(np.sum(per_patch == n)), 4), np.float32)
            rows[:, :2] = self.patches[per_patch == n]
            self.buckets[int(n)] = (rgba_texture(rows), len(rows))
            self.patch_bytes += rows.nbytes

    def draw(self, view_projection, viewport_width, color=(0.8, 0.8, 0.8, 1.0), lit=True, clamp=False,
             max_radius=0.0, lighting=None, wireframe=False):
        """Draw into the bound framebuffer. view_projection: (4, 4) row-major, object space to clip; lighting: an
        `offscreen.ViewLighting` to light as the viewport does, or None for the check shade; wireframe: the edges
        of the tubes' triangles instead."""
        shader = loader.shader("tube_preview", _describe)
        vp = np.asarray(view_projection, np.float64)
        set_shading(shader, vp, color, lit, lighting)
        shader.uniform_float("inverse_view_projection", np.linalg.inv(vp).astype(np.float32).T.ravel().tolist())
        shader.uniform_float("clamp_radius", (1.0 if clamp else 0.0, max_radius))
        shader.uniform_float("viewport_width", float(viewport_width))
        shader.uniform_int("tex_width", TEX_WIDTH)
        shader.uniform_sampler("sections", self.sections)
        for n, (texture, count) in self.buckets.items():
            shader.uniform_float("sides", float(n))
            shader.uniform_sampler("patches", texture)
            pattern_batch(shader, n, wireframe).draw_instanced(shader, instance_start=0, instance_count=count)

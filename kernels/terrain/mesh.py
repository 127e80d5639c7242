"""Crack-free terrain mesh from per-tile levels (a `terrain_lod.Selection`): welded, one pattern per class.

Each tile is a quad domain with four edge segment counts and an inner count along x and along y (from `partition`;
the two differ only where a partial tile is longer one way). Its pattern: an inner grid of ``m - 1`` rows of
``n - 1`` points, each cell split along its (i, j)-(i+1, j+1) diagonal, and four strips that zip the edge points to
the grid's outer ring (a monotone merge of two parallel rows of points). A tile whose inner count across is 1 and
whose two opposite sides have one segment each (a tile one texel thick, since levels never exceed a length in
texels) is one strip zipping its two other sides (two triangles when all four sides have one segment); otherwise
both inner counts are at least 2, so a ring exists. With `terrain_lod.select`'s caps (a side's level at most its
length in texels, the inner level along each axis at most the tile's length along it) a tile never has more
triangles than its full grid, and at the top level it is its full grid: every sample a vertex (EQUAL spacing;
FRACTIONAL_EVEN needs two segments on a side one texel long).

Vertices are welded by construction: a tile corner is one vertex for four tiles, an edge point one vertex
for its two tiles (edges run +x or +y, so both tiles read the same points), inner points belong to their
tile. A shared edge therefore cannot crack. Culled tiles emit no triangles; where the map's no-data voids are cut
(`HeightMap.void_at`), so is every triangle with a corner whose bilinear footprint reads a void; unused vertices are
dropped.
Triangles are counter-clockwise seen from +z.
"""

from dataclasses import dataclass

import numpy as np

from ..common.partition import clamp_levels, point_params, segment_counts
from ..common.quad_pattern import pattern, pattern_codes  # noqa: F401 (the tiles' patterns; the GPU path reads them here)
from .analysis import tile_bounds
from .lod import to_world


@dataclass
class TerrainMesh:
    """positions (n, 3) float32 (terrain-local world), uvs (n, 2) float32 (x / (W-1), y / (H-1)),
    samples (n, 2) float64 (sample coordinates), triangles (m, 3) int32."""

    positions: np.ndarray
    uvs: np.ndarray
    samples: np.ndarray
    triangles: np.ndarray


def _tile_counts(selection):
    """Edge segment counts (nty, ntx, 4) and the inner counts the patterns use along x and y: two (nty, ntx)."""
    sp = selection.spacing
    hc, vc = segment_counts(selection.h_edges, sp), segment_counts(selection.v_edges, sp)
    ec = np.stack([hc[:-1], vc[:, 1:], hc[1:], vc[:, :-1]], -1)  # per tile: BOTTOM, RIGHT, TOP, LEFT
    n, m = (c.astype(np.int64) for c in selection.inner_counts)
    # the patterns' strips (no inner grid): along x when the left and right sides are one segment and m is 1,
    # along y when the bottom and top are and n is 1; any other count of 1 becomes 2 (a ring must exist)
    strip = (((ec[..., 1] == 1) & (ec[..., 3] == 1) & (m == 1)) | ((ec[..., 0] == 1) & (ec[..., 2] == 1) & (n == 1)))
    return ec, np.where((n == 1) & ~strip, 2, n), np.where((m == 1) & ~strip, 2, m)


def triangle_count(selection):
    """Triangles `bake` will make, without making them (for memory guards and benchmarks): int."""
    ec, n, m = _tile_counts(selection)
    strip = (n == 1) | (m == 1)
    ring = ec.sum(-1) + 2 * (n - 2) + 2 * (m - 2) + 2 * (n - 2) * (m - 2)
    per_tile = np.where(strip, ec.sum(-1) - 2, ring)
    return int(per_tile[~selection.culled].sum())


def pattern_classes(selection):
    """Tiles grouped by pattern: dict (c0, c1, c2, c3, n, m) -> visible tile indices (row-major) int64."""
    ec, n, m = _tile_counts(selection)
    keys = np.concatenate([ec.reshape(-1, 4), n.reshape(-1, 1), m.reshape(-1, 1)], 1)
    visible = np.nonzero(~selection.culled.ravel())[0]
    classes, inverse = np.unique(keys[visible], axis=0, return_inverse=True)
    inverse = inverse.ravel()
    return {tuple(int(v) for v in key): visible[inverse == k] for k, key in enumerate(classes)}


def _edge_points(levels, spacing, fixed, lo, hi, along_x):
    """Interior points of a family of edges: counts (k,), first index (k,), sample coords (total, 2)."""
    counts = segment_counts(levels, spacing).ravel()
    f = clamp_levels(levels, spacing).ravel()
    first = np.concatenate([[0], np.cumsum(counts - 1)])[:-1]
    edge = np.repeat(np.arange(counts.size), counts - 1)
    k = np.arange(edge.size) - first[edge] + 1
    t = point_params(f[edge], counts[edge], k, spacing)
    a, b, c = lo.ravel()[edge], hi.ravel()[edge], fixed.ravel()[edge]
    pos = a + t * (b - a)
    xy = np.stack([pos, c], 1) if along_x else np.stack([c, pos], 1)
    return counts.reshape(levels.shape), first.reshape(levels.shape), xy


def bake(hm, table, selection):
    """The terrain mesh of a selection (`TerrainMesh`)."""
    ntx, nty = table.counts
    ts, spacing = table.tile_size, selection.spacing
    xb = np.concatenate([tile_bounds(np.arange(ntx), ts, hm.width)[0], [hm.width - 1]]).astype(np.float64)
    yb = np.concatenate([tile_bounds(np.arange(nty), ts, hm.height)[0], [hm.height - 1]]).astype(np.float64)
    gy, gx = np.meshgrid(yb, xb, indexing="ij")
    corners = np.stack([gx.ravel(), gy.ravel()], 1)  # (nty + 1) * (ntx + 1), row-major
    hc, hf, hxy = _edge_points(selection.h_edges, spacing, gy[:, :-1], gx[:, :-1], gx[:, 1:], True)
    vc, vf, vxy = _edge_points(selection.v_edges, spacing, gx[:-1, :], gy[:-1, :], gy[1:, :], False)
    _, n, m = _tile_counts(selection)
    # EQUAL spacing ignores the levels; a forced 2 stays exact
    f_x, f_y = (clamp_levels(level, spacing) for level in selection.inner_levels)
    # inner grid points per tile, row-major, (m - 1) rows of (n - 1)
    nx, ny = (n - 1).ravel(), (m - 1).ravel()
    per_tile = nx * ny
    inner_first = np.concatenate([[0], np.cumsum(per_tile)])[:-1]
    tile = np.repeat(np.arange(per_tile.size), per_tile)
    local = np.arange(tile.size) - inner_first[tile]
    row = np.maximum(nx[tile], 1)
    i, j = local % row + 1, local // row + 1
    ti = point_params(f_x.ravel()[tile], n.ravel()[tile], i, spacing)
    tj = point_params(f_y.ravel()[tile], m.ravel()[tile], j, spacing)
    tx, ty = tile % ntx, tile // ntx
    ixy = np.stack([xb[tx] + ti * (xb[tx + 1] - xb[tx]), yb[ty] + tj * (yb[ty + 1] - yb[ty])], 1)
    n_c, n_h = corners.shape[0], hxy.shape[0]
    base_in = n_c + n_h + vxy.shape[0]
    samples = np.concatenate([corners, hxy, vxy, ixy])
    tri_parts = []
    for key, tiles in pattern_classes(selection).items():
        c = key[:4]
        tmpl = pattern(*key)
        tyi, txi = tiles // ntx, tiles % ntx
        cols = [tyi * (ntx + 1) + txi, tyi * (ntx + 1) + txi + 1, (tyi + 1) * (ntx + 1) + txi + 1,
                (tyi + 1) * (ntx + 1) + txi]
        starts = (n_c + hf[tyi, txi], n_c + n_h + vf[tyi, txi + 1], n_c + hf[tyi + 1, txi], n_c + n_h + vf[tyi, txi])
        for s in range(4):
            cols += [starts[s] + q for q in range(c[s] - 1)]
        inner_points = (key[4] - 1) * (key[5] - 1)
        cols += [base_in + inner_first[tiles] + q for q in range(inner_points)]
        lmap = np.stack(cols, 1)
        tri_parts.append(lmap[:, tmpl].reshape(-1, 3))
    tris = np.concatenate(tri_parts) if tri_parts else np.zeros((0, 3), np.int64)
    used = np.zeros(samples.shape[0], bool)
    used[tris.ravel()] = True
    holes = hm.void_at(samples[used, 0], samples[used, 1])  # no-data cut: a triangle with a corner on a void goes
    if holes is not None and holes.any():  # (asked of the used points only: a block reads only its own samples)
        on_void = np.zeros(samples.shape[0], bool)
        on_void[used] = holes
        tris = tris[~on_void[tris].any(axis=1)]
        used[:] = False
        used[tris.ravel()] = True
    remap = np.cumsum(used) - 1
    samples = samples[used]
    z = hm.sample(samples[:, 0], samples[:, 1])
    positions = to_world(hm, samples[:, 0], samples[:, 1], z).astype(np.float32)
    uvs = (samples / [hm.width - 1, hm.height - 1]).astype(np.float32)
    return TerrainMesh(positions, uvs, samples, remap[tris].astype(np.int32))


def full_grid(hm):
    """The full-resolution grid (one quad per texel, [Nunes 2011]'s "no LOD" reference): `TerrainMesh`."""
    h, w = hm.height, hm.width
    gy, gx = np.meshgrid(np.arange(h, dtype=np.float64), np.arange(w, dtype=np.float64), indexing="ij")
    samples = np.stack([gx.ravel(), gy.ravel()], 1)
    v = np.arange(h * w).reshape(h, w)
    a, b, c, d = v[:-1, :-1].ravel(), v[:-1, 1:].ravel(), v[1:, 1:].ravel(), v[1:, :-1].ravel()
    tris = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)]).astype(np.int32)
    positions = to_world(hm, gx.ravel(), gy.ravel(), hm.heights().ravel()).astype(np.float32)
    return TerrainMesh(positions, (samples / [w - 1, h - 1]).astype(np.float32), samples, tris)

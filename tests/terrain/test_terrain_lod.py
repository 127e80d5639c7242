"""Terrain levels and meshes: [Nunes 2011]'s rules, crack-free edges from random cameras, holes, culling, peaks."""

from dataclasses import replace

import numpy as np
import pytest
from mesh_checks import assert_parts_weld_into
from tessera.kernels.common.camera import Camera
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.terrain import analysis as ta
from tessera.kernels.terrain import heightmap_io as hio
from tessera.kernels.terrain import lod as tl
from tessera.kernels.terrain import mesh as tm
from tessera.kernels.terrain.sample_grid import SampleGrid


def _terrain(size=257, seed=0):
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:size, 0:size] / size
    h = 40 * np.sin(5 * x + rng.random()) * np.cos(4 * y) + 15 * np.sin(23 * x * y)
    h[(x - 0.7) ** 2 + (y - 0.3) ** 2 < 0.01] += 30  # a mesa with a cliff
    h[:, : size // 4] = 0.0  # a flat plain
    return hio.from_array(h.astype(np.float32), texel_size=2.0)


def _random_camera(rng, hm, lowest=20.0, target_z=0.0, far=20.0):
    """A camera somewhere over the terrain (at least ``lowest`` up) looking at a point of it at height ``target_z``;
    the clip end ``far`` half-widths away."""
    half = (hm.width - 1) * hm.texel_size * 0.5
    eye = rng.uniform(-2 * half, 2 * half, 3)
    eye[2] = rng.uniform(lowest, 3 * half)
    target = np.append(rng.uniform(-half, half, 2), target_z)
    return Camera.looking_at(eye, target, fov_deg=rng.uniform(25, 70), width=640, height=360, far=far * half)


def _boundary_edges(tris):
    e = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    u, c = np.unique(e, axis=0, return_counts=True)
    return u[c == 1], c


def test_g_and_the_distance_law_follow_the_seed():
    s = tl.TerrainLod()
    assert tl.g_of_ham(0.0, s) == 1.0 and tl.g_of_ham(1e9, s) == 64.0
    assert tl.g_of_ham(0.0, tl.TerrainLod(g="LOG")) == 1.0
    assert tl.g_of_ham(9.0, s) == pytest.approx(12.0)  # 4 sqrt(9)
    rng = np.random.default_rng(1)
    for _ in range(50):
        t_max = rng.uniform(1, 64)
        t_min = rng.uniform(1, t_max)
        d_max = rng.uniform(1, 100)
        d_min = d_max * np.sqrt(t_max / t_min)  # (5-7)
        d = np.sort(rng.uniform(0, 5 * d_min, 400))
        t = tl.inverse_square_level(d, t_max, t_min, d_max)
        assert np.all(np.diff(t) <= 0) and t.max() <= t_max and t.min() >= t_min
        assert tl.inverse_square_level(d_max * 0.999, t_max, t_min, d_max) == t_max
        eps = 1e-7 * d_max
        for at in (d_max, d_min):  # continuous at both ends of the interval
            assert abs(tl.inverse_square_level(at - eps, t_max, t_min, d_max)
                       - tl.inverse_square_level(at + eps, t_max, t_min, d_max)) < 1e-4 * t_max
        mid = 0.5 * (d_max + d_min)
        assert tl.inverse_square_level(mid, t_max, t_min, d_max) == pytest.approx(t_max * d_max**2 / mid**2)


def test_a_flat_tile_gets_level_one_at_every_distance():
    hm = _terrain()
    table = ta.tile_table(hm, 32, backend="numpy")
    flat = table.ham_max == 0
    assert flat[:, 0].all()  # the plain
    for dist in (5.0, 50.0, 500.0, 5000.0):
        cam = Camera.looking_at((-200.0, -dist, 30.0), (-200.0, 0.0, 0.0), far=1e5)
        sel = tl.select(hm, table, cam, tl.TerrainLod(levels="FRACTIONAL", culling=False))
        assert np.all(sel.inner[:, 0] == 1.0) and np.all(sel.t_max[flat] == 1.0)
        assert np.all(sel.edge[:, 0, 3] == 1.0)  # the plain's outer edges touch no rough tile


@pytest.mark.parametrize("levels", ["FRACTIONAL", "INTEGER", "POW2"])
def test_random_cameras_shared_edges_agree_bit_for_bit_and_meshes_have_no_holes(levels):
    hm = _terrain(seed=2)
    table = ta.tile_table(hm, 32, backend="numpy")
    rng = np.random.default_rng(7)
    for _ in range(12):
        cam = _random_camera(rng, hm)
        sel = tl.select(hm, table, cam, tl.TerrainLod(levels=levels, culling=False))
        assert np.array_equal(sel.edge[1:, :, 0], sel.edge[:-1, :, 2])  # BOTTOM of a tile == TOP of the one below
        assert np.array_equal(sel.edge[:, 1:, 3], sel.edge[:, :-1, 1])  # LEFT == RIGHT of the left neighbour
        assert sel.edge.max() <= 64 and sel.edge.min() >= 1
        assert np.all(sel.edge <= np.maximum(sel.t_max[..., None], 64))
        mesh = tm.bake(hm, table, sel)
        assert len(mesh.triangles) == tm.triangle_count(sel)
        boundary, counts = _boundary_edges(mesh.triangles)
        s = mesh.samples[boundary]  # (k, 2 ends, xy)
        on_border = ((s[..., 0] == 0).all(1) | (s[..., 0] == hm.width - 1).all(1)
                     | (s[..., 1] == 0).all(1) | (s[..., 1] == hm.height - 1).all(1))
        assert on_border.all() and counts.max() == 2  # closed inside, manifold
        p = mesh.samples[mesh.triangles]
        e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
        cross = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
        assert cross.min() > 0 and cross.sum() / 2 == pytest.approx((hm.width - 1) * (hm.height - 1))
        assert np.isfinite(mesh.positions).all()


def test_culled_tiles_produce_no_triangles():
    hm = _terrain(seed=3)
    table = ta.tile_table(hm, 32, backend="numpy")
    rng = np.random.default_rng(4)
    seen_culled = 0
    for _ in range(10):
        cam = _random_camera(rng, hm)
        sel = tl.select(hm, table, cam, tl.TerrainLod(culling=True))
        seen_culled += sel.culled.sum()
        mesh = tm.bake(hm, table, sel)
        assert len(mesh.triangles) == tm.triangle_count(sel)
        if not len(mesh.triangles):
            assert sel.culled.all()
            continue
        centre = mesh.samples[mesh.triangles].mean(axis=1)
        tile = (np.minimum(centre[:, 1] // 32, 7).astype(int), np.minimum(centre[:, 0] // 32, 7).astype(int))
        assert not sel.culled[tile].any()
        # a culled tile's box projects outside the view: its 8 corners fail one clip plane
        assert sel.culled.sum() < sel.culled.size or len(mesh.triangles) == 0
    assert seen_culled > 0


def test_culling_by_box_maxima_equals_the_eight_corner_test():
    hm = _terrain(seed=3)
    table = ta.tile_table(hm, 32, backend="numpy")
    rng = np.random.default_rng(9)
    xb, yb = ta.tile_bounds(np.arange(8), 32, hm.width), ta.tile_bounds(np.arange(8), 32, hm.height)
    culled = 0
    for _ in range(20):
        cam = _random_camera(rng, hm)
        sel = tl.select(hm, table, cam, tl.TerrainLod(culling=True))
        m = np.asarray(cam.projection) @ np.asarray(cam.view)
        for ty in range(8):
            for tx in range(8):
                corners = np.array([tl.to_world(hm, x[tx], y[ty], z[ty, tx])
                                    for x in xb for y in yb for z in (table.h_min, table.h_max)])
                c = np.concatenate([corners.reshape(-1, 3), np.ones((8, 1))], 1) @ m.T
                out = any(np.all(c[:, a] < -c[:, 3]) or np.all(c[:, a] > c[:, 3]) for a in range(3))
                assert sel.culled[ty, tx] == out
        culled += sel.culled.sum()
    assert 0 < culled < 20 * 64


def test_pow2_levels_are_the_next_power_of_two():
    f = np.array([1.0, 1.0000001, 1.5, 2.0, 2.0000001, 3.0, 4.0, 5.5, 8.0, 31.9, 32.0, 33.0, 64.0])
    want = np.array([1, 2, 2, 2, 4, 4, 4, 8, 8, 32, 32, 64, 64], float)
    assert np.array_equal(tl._round(f, tl.TerrainLod(levels="POW2")), want)


def test_culling_keeps_every_tile_in_view():
    hm = _terrain(seed=3)
    table = ta.tile_table(hm, 32, backend="numpy")
    cam = Camera.looking_at((0.0, 0.0, 4000.0), (0.0, 1e-3, 0.0), fov_deg=40, far=1e5)  # whole map in view
    assert not tl.select(hm, table, cam, tl.TerrainLod(culling=True)).culled.any()


def _mesh_height_at(mesh, x, y):
    p = mesh.samples[mesh.triangles]
    a, b, c = p[:, 0], p[:, 1], p[:, 2]
    den = (b[:, 1] - c[:, 1]) * (a[:, 0] - c[:, 0]) + (c[:, 0] - b[:, 0]) * (a[:, 1] - c[:, 1])
    l1 = ((b[:, 1] - c[:, 1]) * (x - c[:, 0]) + (c[:, 0] - b[:, 0]) * (y - c[:, 1])) / den
    l2 = ((c[:, 1] - a[:, 1]) * (x - c[:, 0]) + (a[:, 0] - c[:, 0]) * (y - c[:, 1])) / den
    l3 = 1 - l1 - l2
    k = np.nonzero((l1 >= -1e-12) & (l2 >= -1e-12) & (l3 >= -1e-12))[0][0]
    z = mesh.positions[mesh.triangles[k], 2].astype(np.float64)
    return l1[k] * z[0] + l2[k] * z[1] + l3[k] * z[2]


@pytest.mark.parametrize("peak", [(150, 80), (129, 97), (200, 200)])
def test_a_tall_thin_peak_far_away_stays_within_epsilon(peak):
    size = 257
    y, x = np.mgrid[0:size, 0:size].astype(np.float64)
    px, py = peak
    h = 300.0 * np.exp(-((x - px) ** 2 + (y - py) ** 2) / (2 * 1.5**2))  # a spire 1.5 texels wide
    hm = hio.from_array(h.astype(np.float32), texel_size=1.0)
    table = ta.tile_table(hm, 32, backend="numpy")
    cam = Camera.looking_at((0.0, -2500.0, 200.0), (0.0, 0.0, 100.0), fov_deg=30, width=1280, height=720, far=1e5)
    settings = tl.TerrainLod(epsilon=3.0, levels="POW2", culling=False)
    sel = tl.select(hm, table, cam, settings)
    ty, tx = min(py // 32, 7), min(px // 32, 7)
    assert sel.t_min[ty, tx] > 1  # still refined although far away
    mesh = tm.bake(hm, table, sel)
    top = tl.to_world(hm, px, py, hm.heights()[py, px])
    base = tl.to_world(hm, px, py, _mesh_height_at(mesh, px, py))
    pix = [tl._project(cam, p[None])[0][0] for p in (top, base)]
    assert np.hypot(*(pix[0] - pix[1])) <= settings.epsilon
    coarse = tl.select(hm, table, cam, tl.TerrainLod(mode="DISTANCE", epsilon=3.0, levels="POW2", culling=False))
    flat_base = tl.to_world(hm, px, py, _mesh_height_at(tm.bake(hm, table, coarse), px, py))
    far = tl._project(cam, flat_base[None])[0][0]
    assert np.hypot(*(pix[0] - far)) > settings.epsilon  # distance alone would lose the spire


def test_t_min_rules_printed_and_corrected():
    hm = _terrain(seed=5)
    table = ta.tile_table(hm, 32, backend="numpy")
    cam = Camera.looking_at((0.0, -300.0, 120.0), (0.0, 0.0, 0.0), far=1e5)
    args = (hm, table, cam)
    xb, yb = ta.tile_bounds(np.arange(8), 32, hm.width), ta.tile_bounds(np.arange(8), 32, hm.height)
    xs = tuple(np.broadcast_to(b[None, :].astype(float), (8, 8)) for b in xb)
    ys = tuple(np.broadcast_to(b[:, None].astype(float), (8, 8)) for b in yb)
    h_hat = tl._peak_error_px(hm, table, cam, xs, ys, 1)
    t_max = np.full((8, 8), 64.0)
    log2 = tl.t_min_levels(*args, tl.TerrainLod(t_min_rule="LOG2"), t_max, xs, ys)
    printed = tl.t_min_levels(*args, tl.TerrainLod(t_min_rule="PRINTED"), t_max, xs, ys)
    with np.errstate(divide="ignore"):
        assert np.allclose(log2, np.clip(np.log2(np.where(h_hat > 0, h_hat / 3.0, 1)), 1, 64))
        assert np.allclose(printed, np.clip(np.log2(np.where(h_hat > 0, 3.0 / h_hat, 1)), 1, 64))
    assert (h_hat > 3.0).any() and np.all(printed[h_hat > 3.0] == 1.0)  # as printed, it never refines
    low = np.full((8, 8), 2.0)
    assert tl.t_min_levels(*args, tl.TerrainLod(), low, xs, ys).max() <= 2.0  # clamped to T_max


def test_fractional_levels_change_the_mesh_continuously():
    hm = _terrain(seed=6)
    table = ta.tile_table(hm, 32, backend="numpy")
    cam = Camera.looking_at((0.0, -300.0, 120.0), (0.0, 0.0, 0.0), far=1e5)
    sel = tl.select(hm, table, cam, tl.TerrainLod(levels="FRACTIONAL", culling=False))

    def mesh_at(level):
        for a in (sel.h_edges, sel.v_edges, sel.inner):
            a[...] = level
        return tm.bake(hm, table, sel)

    for n in (4.0, 6.0, 8.0):
        a, b = mesh_at(n - 1e-9), mesh_at(n + 1e-9)  # across a change of segment count
        assert len(b.triangles) > len(a.triangles)
        pa, pb = a.positions.astype(np.float64), b.positions.astype(np.float64)
        assert _farthest_from(pb, pa) < 1e-3  # the new vertices sit on old ones
        assert _farthest_from(pa, pb) < 1e-3


def _farthest_from(points, others):
    """Largest distance from a point of ``points`` to its nearest point of ``others`` (brute force, chunked)."""
    worst = 0.0
    for chunk in np.array_split(points, max(1, len(points) // 256)):
        d = ((chunk[:, None, :] - others[None, :, :]) ** 2).sum(-1).min(axis=1)
        worst = max(worst, float(np.sqrt(d.max())))
    return worst


def test_uniform_mode_at_64_is_the_full_grid():
    hm = _terrain(size=129)
    table = ta.tile_table(hm, 64, backend="numpy")
    cam = Camera.looking_at((0.0, -300.0, 120.0), (0.0, 0.0, 0.0), far=1e5)
    sel = tl.select(hm, table, cam, tl.TerrainLod(mode="UNIFORM", culling=False))
    mesh, full = tm.bake(hm, table, sel), tm.full_grid(hm)
    assert len(mesh.triangles) == len(full.triangles) == 2 * 128 * 128
    order = np.lexsort(mesh.samples.T)
    assert np.array_equal(mesh.samples[order], full.samples[np.lexsort(full.samples.T)])
    assert np.array_equal(mesh.positions[order], full.positions[np.lexsort(full.samples.T)])


def test_bad_settings_are_refused():
    with pytest.raises(InvalidInputError):
        tl.TerrainLod(mode="CDLOD")
    with pytest.raises(InvalidInputError):
        tl.TerrainLod(max_level=65)
    with pytest.raises(InvalidInputError):
        tl.TerrainLod(epsilon=0.0)
    hm = _terrain(size=65)
    table = ta.tile_table(hm, 16, backend="numpy")
    with pytest.raises(InvalidInputError, match="different height map"):
        tl.select(_terrain(size=129), table, Camera.looking_at((0, -9, 9), (0, 0, 0)))


@pytest.mark.parametrize("size, tile", [((7, 5), 64), ((2, 2), 16), ((66, 3), 64), ((40, 97), 32), ((33, 65), 8),
                                        ((257, 201), 64)])
@pytest.mark.parametrize("mode, levels", [("UNIFORM", "INTEGER"), ("OURS", "POW2"), ("DISTANCE", "FRACTIONAL")])
def test_a_mesh_never_outgrows_its_full_grid(size, tile, mode, levels):
    """Tiles larger than the map, and the last partial row and column (one texel thick included), get no more
    segments per side than the side has texels: never more triangles than the full grid, UNIFORM at the top
    level over whole tiles *is* the full grid, and the mesh stays closed with no crack."""
    w, h = size
    rng = np.random.default_rng(w * 1000 + h)
    hm = hio.from_array((rng.random((h, w)) * 30).astype(np.float32), texel_size=1.0)
    table = ta.tile_table(hm, tile, backend="numpy")
    cam = Camera.looking_at((0.0, -0.5, 3.0), (0.0, 0.0, 0.0), far=1e5)  # close: the highest levels
    sel = tl.select(hm, table, cam, tl.TerrainLod(mode=mode, levels=levels, culling=False, ham_scale=64.0))
    mesh, full = tm.bake(hm, table, sel), tm.full_grid(hm)
    assert len(mesh.triangles) == tm.triangle_count(sel)
    thin = 1 in ((w - 1) % tile, (h - 1) % tile, w - 1, h - 1)  # a side one texel long
    if levels != "FRACTIONAL" or not thin:  # fractional-even spacing has two segments at least
        assert len(mesh.triangles) <= len(full.triangles)
    if mode == "UNIFORM":  # partial tiles too: their inner grid is as long as they are along each axis
        assert len(mesh.triangles) == len(full.triangles)
        assert np.array_equal(np.unique(mesh.samples, axis=0), np.unique(full.samples, axis=0))
    boundary, counts = _boundary_edges(mesh.triangles)
    s = mesh.samples[boundary]
    on_border = ((s[..., 0] == 0).all(1) | (s[..., 0] == w - 1).all(1)
                 | (s[..., 1] == 0).all(1) | (s[..., 1] == h - 1).all(1))
    assert on_border.all() and counts.max() == 2
    p = mesh.samples[mesh.triangles]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    cross = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    assert cross.min() > 0 and cross.sum() / 2 == pytest.approx((w - 1) * (h - 1))


class _Reads(SampleGrid):
    """Float32 samples that mark every sample read, through windows or points."""

    def __init__(self, a):
        self.a, self.shape = a, a.shape
        self.read = np.zeros(a.shape, bool)

    def window(self, y0, y1, x0, x1):
        self.read[y0:y1, x0:x1] = True
        return self.a[y0:y1, x0:x1].copy()

    def points(self, ys, xs):
        self.read[ys, xs] = True
        return self.a[ys, xs]


@pytest.mark.parametrize("split", [(2, 2), (3, 2), (4, 4), (9, 1)])
def test_the_blocks_of_a_split_weld_into_the_whole_mesh_reading_only_their_region(split, monkeypatch):
    """Farm tasks mesh one block each (`select` with ``block``) from a table analysed over the block and its ring of
    tiles only: each reads no sample outside that region and the analysis' halo, and their meshes, welded where
    positions coincide bit for bit, are the whole mesh; every triangle comes from exactly one block. A map with
    partial tiles; the selection calls no LAPACK (CPU-dependent)."""
    full = _terrain(size=201, seed=5)
    hm = replace(full, samples=np.ascontiguousarray(full.samples[:193]))  # 13 x 12 tiles of 16, the last column partial
    ts = 16
    table = ta.tile_table(hm, ts, backend="numpy")
    rng = np.random.default_rng(sum(split))
    monkeypatch.setattr(np.linalg, "inv", None)  # any use would raise: the levels must be the same on every machine
    for levels, rule in (("FRACTIONAL", "SEARCH"), ("POW2", "LOG2")):
        cam = _random_camera(rng, hm, far=50.0)
        settings = tl.TerrainLod(levels=levels, t_min_rule=rule, epsilon=1.0)
        whole = tm.bake(hm, table, tl.select(hm, table, cam, settings))
        assert len(whole.triangles) > 500
        cols, rows = split
        parts = []
        for r in range(rows):
            for c in range(cols):
                block = (c, r, cols, rows)
                reads = _Reads(hm.samples)
                task = replace(hm, samples=reads)
                region = tl.block_region(block, table.counts)
                task_table = ta.tile_table(task, ts, tiles=region)
                parts.append(tm.bake(task, task_table, tl.select(task, task_table, cam, settings, block=block)))
                tx0, ty0, tx1, ty1 = region
                allowed = np.zeros(hm.samples.shape, bool)
                allowed[max(0, ty0 * ts - 2):ty1 * ts + 3, max(0, tx0 * ts - 2):tx1 * ts + 3] = True
                assert reads.read.any() and not (reads.read & ~allowed).any(), block
        assert_parts_weld_into(parts, whole)


def test_a_block_outside_its_split_is_refused():
    with pytest.raises(InvalidInputError, match="Block 2, 0 of a 2 x 2 split does not exist"):
        tl.block_tiles((2, 0, 2, 2), (8, 8))
    assert tl.block_tiles((1, 0, 3, 1), (8, 5)) == (range(2, 5), range(0, 5))
    assert tl.block_tiles((0, 1, 1, 4), (8, 2)) == (range(0, 8), range(0, 1))

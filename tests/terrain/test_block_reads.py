"""Farm blocks of elevation files: a task reads only its block, its ring of tiles and the filled voids there (from the
void index the plan writes once), and the blocks join into exactly the one-process mesh."""

import os

import numpy as np
import pytest
from mesh_checks import assert_parts_weld_into
from tessera.kernels.common.camera import Camera
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.terrain import analysis as ta
from tessera.kernels.terrain import geotiff as gt
from tessera.kernels.terrain import lod as tl
from tessera.kernels.terrain import mesh as tm
from tessera.kernels.terrain import sample_grid
from tessera.kernels.terrain.void_fill import CELL

from tools.geotiff_files import write_geotiff
from tools.ridged_terrain import ridged_terrain

TS = 32  # tile size of the terrain (samples)
FILE_TILE = 64  # tile size of the file


def _dem(h=449, w=515):
    """Top-first heights with voids: a lake across block borders, a bay on the map's edge, a thin river that spans
    several blocks, and one void sample."""
    top = (ridged_terrain(max(h, w), seed=8, octaves=5)[:h, :w] * 800.0 + 50.0).astype(np.float32)
    top[200:260, 230:300] = np.nan
    top[:40, 470:] = np.nan
    top[100:103, 20:480] = np.nan
    top[400, 77] = np.nan
    return top


@pytest.fixture
def dem(tmp_path):
    path = str(tmp_path / "dem.tif")
    write_geotiff(path, np.nan_to_num(_dem(), nan=-9999.0), nodata=-9999.0, tile=(FILE_TILE, FILE_TILE))
    return path


def _camera(hm):
    half = 0.5 * (hm.width - 1) * hm.texel[0]
    return Camera.looking_at((0.3 * half, -1.4 * half, 0.7 * half), (0.0, 0.1 * half, 0.0), width=960, height=540,
                             far=1e7)


class _Decoded:
    """Records the file blocks (top-first rows and columns) every source is asked for, kept or decoded."""

    def __init__(self, monkeypatch):
        self.windows = []
        real = sample_grid.BlockSource._span

        def span(source, bi, bj):
            rows, cols = source.block_rows, source.block_cols or source.shape[1]
            self.windows.append((bi * rows, (bi + 1) * rows, bj * cols, (bj + 1) * cols))
            return real(source, bi, bj)

        monkeypatch.setattr(sample_grid.BlockSource, "_span", span)


@pytest.mark.parametrize("voids", ["FILL", "HOLES"])
def test_farm_blocks_read_only_their_region_and_join_into_the_whole_mesh(dem, tmp_path, monkeypatch,
                                                                         elevation_reader, voids):
    # blocks of one file tile, so what a task decodes is near what it needs
    monkeypatch.setattr(sample_grid, "BLOCK_ROWS", FILE_TILE)
    monkeypatch.setattr(sample_grid, "BLOCK_COLS", FILE_TILE)
    from tessera.kernels.terrain import gdal_raster

    monkeypatch.setattr(gdal_raster, "BLOCK_ROWS", FILE_TILE)
    hm, _ = gt.read_geotiff([dem], voids=voids)
    assert hm.samples.void_count > 5000
    table = ta.tile_table(hm, TS, backend="numpy")
    cam = _camera(hm)
    settings = tl.TerrainLod(epsilon=1.0, levels="FRACTIONAL")
    whole = tm.bake(hm, table, tl.select(hm, table, cam, settings))
    assert len(whole.triangles) > 3000

    index = str(tmp_path / "dem.voids")
    assert gt.write_void_index([dem], index, voids=voids) == hm.samples.void_count
    decoded = _Decoded(monkeypatch)
    parts, cols, rows = [], 3, 3
    h, w = hm.height, hm.width
    for r in range(rows):
        for c in range(cols):
            block = (c, r, cols, rows)
            decoded.windows.clear()
            task, _ = gt.read_geotiff([dem], voids=voids, void_index=index)
            assert task.hold(tl.block_window(block, table.counts, TS, (h, w)))  # as the terrain operator does
            region = tl.block_region(block, table.counts)
            task_table = ta.tile_table(task, TS, tiles=region)
            parts.append(tm.bake(task, task_table, tl.select(task, task_table, cam, settings, block=block)))
            # every decoded block meets the region grown by the analysis' halo (bottom-first rows -> file rows)
            tx0, ty0, tx1, ty1 = region
            x0, x1 = max(0, tx0 * TS - 2), min(w, tx1 * TS + 3)
            top0, top1 = h - min(h, ty1 * TS + 3), h - max(0, ty0 * TS - 2)
            assert decoded.windows and len(set(decoded.windows)) == len(decoded.windows)  # each block decoded once
            for a, b, left, right in decoded.windows:
                assert a < top1 and b > top0 and left < x1 and right > x0, (block, (a, b, left, right))
            area = sum((min(b, h) - a) * (min(right, w) - left) for a, b, left, right in set(decoded.windows))
            assert area <= ((top1 - top0) + 2 * FILE_TILE) * ((x1 - x0) + 2 * FILE_TILE)
    assert_parts_weld_into(parts, whole)


def test_the_void_index_gives_every_filled_value_of_the_scan(dem, tmp_path):
    """Windows and points through the index equal the scanned grid's, bit for bit, voids and all."""
    scanned, _ = gt.read_geotiff([dem], voids="HOLES")
    index = str(tmp_path / "v.voids")
    gt.write_void_index([dem], index, voids="HOLES")
    indexed, _ = gt.read_geotiff([dem], voids="HOLES", void_index=index)
    a, b = scanned.samples, indexed.samples
    assert b.void_count == a.void_count and np.array_equal(a.labels, b.labels)
    rng = np.random.default_rng(2)
    for _ in range(20):
        y0, x0 = rng.integers(0, 400), rng.integers(0, 470)
        y1, x1 = y0 + rng.integers(1, 120), x0 + rng.integers(1, 160)
        wa, wb = a[y0:y1, x0:x1], b[y0:y1, x0:x1]
        assert np.isfinite(wa).all() and wa.tobytes() == wb.tobytes()
    ys, xs = rng.integers(0, 449, 5000), rng.integers(0, 515, 5000)
    assert a[ys, xs].tobytes() == b[ys, xs].tobytes()
    sx, sy = rng.uniform(0, 514, 3000), rng.uniform(0, 448, 3000)
    assert np.array_equal(scanned.void_at(sx, sy), indexed.void_at(sx, sy)) and scanned.void_at(sx, sy).any()


def test_a_void_index_of_other_data_or_settings_is_refused(dem, tmp_path):
    index = str(tmp_path / "v.voids")
    gt.write_void_index([dem], index, voids="FILL")
    with pytest.raises(InvalidInputError, match="has the voids filled; this task asks otherwise"):
        gt.read_geotiff([dem], voids="HOLES", void_index=index)
    other = str(tmp_path / "other.tif")
    changed = np.nan_to_num(_dem(), nan=-9999.0)
    changed[300, 300] += 1.0
    write_geotiff(other, changed, nodata=-9999.0, tile=(FILE_TILE, FILE_TILE))
    made = os.stat(dem).st_mtime_ns
    os.replace(other, dem)
    os.utime(dem, ns=(made + 5 * 10**9, made + 5 * 10**9))  # edited a few seconds later
    with pytest.raises(InvalidInputError, match="made of other data than dem.tif .*make the farm plan again"):
        gt.read_geotiff([dem], void_index=index)
    gt.write_void_index([dem], index)
    with open(index, "rb+") as f:
        f.truncate(os.path.getsize(index) - 100)
    with pytest.raises(InvalidInputError, match="cut short or damaged"):
        gt.read_geotiff([dem], void_index=index)
    with pytest.raises(InvalidInputError, match="cannot be read"):
        gt.read_geotiff([dem], void_index=str(tmp_path / "missing.voids"))


def test_a_void_index_keeps_only_the_void_cells():
    """The index stores a cell of values per void cell, not the components' bounding boxes: a thin diagonal void
    costs its cells only."""
    top = (ridged_terrain(1025, seed=1, octaves=4) * 100).astype(np.float32)
    for i in range(1025):
        top[i, min(1024, i):min(1025, i + 3)] = np.nan
    from tessera.kernels.terrain.void_fill import FilledGrid

    grid = FilledGrid(_Array(top[::-1].copy()))
    cells = len(grid._cells.values)
    box = (1025 // CELL + 1) ** 2  # the component's bounding box: the whole map
    assert grid.labels.max() == 1 and cells <= 3 * (1025 // CELL + 1) and cells < 0.15 * box


class _Array(sample_grid.SampleGrid):
    def __init__(self, a):
        self.a, self.shape = a, a.shape

    def window(self, y0, y1, x0, x1):
        return self.a[y0:y1, x0:x1]

    def points(self, ys, xs):
        return self.a[ys, xs]

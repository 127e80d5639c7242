"""GeoTIFF elevation data out of core: a 16385² float32 DEM, tiled 256² and deflate-compressed, with voids.

- ``geotiff_out_of_core``: the GeoTIFF read block by block (voids found and filled) and analysed into the tile table,
  against the baseline of the same heights as a raw .r32 file analysed memory-mapped (the out-of-core path that
  needs no decoding), same run: wall time of each and their ratio, peak Python-side allocation (tracemalloc)
  against the size of the map as float32 (1 GiB: what a reader that decodes the whole file, as BlenderGIS does,
  holds at least), and the files' sizes.
- ``gdal_reader``: the same GeoTIFF read through GDAL (the bundled rasterio, the default) against the TIFF reader
  (tifffile tags, OpenImageIO blocks: the reader before GDAL and the fallback where it does not load), each read and
  analysed in a fresh process, same run: wall time of each and their ratio, the peak resident memory's growth over
  the process's memory before the read (GDAL allocates outside Python, so tracemalloc cannot see it), and whether
  the two tile tables are identical.
- ``block_task``: the 16 tasks of a 4 x 4 farm split against one process meshing the whole terrain, each in a fresh
  process: wall time and bytes read (``/proc/self/io`` rchar: the DEM and the void index) against the file's size,
  the plan's one pass that finds and fills the voids (the void index) likewise, the largest task's triangles against
  the whole mesh's, and whether the 16 meshes, welded where positions coincide bit for bit, are the whole mesh.
- ``geotiff_split``: the same DEM cut into four files (adjacent tiles) read as one terrain, against the single file:
  time ratio and whether the tile tables are identical.
Prints one JSON object per case. Run: make bench, or .venv/bin/python bench/geotiff.py
"""

import atexit
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import tracemalloc

import numpy as np
from _setup import import_path

import_path()
from tessera.kernels.terrain import geotiff as gt  # noqa: E402
from tessera.kernels.terrain import heightmap_io as hio  # noqa: E402
from tessera.kernels.terrain.analysis import tile_counts, tile_table  # noqa: E402
from tessera.tools.geotiff_files import write_geotiff  # noqa: E402
from tessera.tools.ridged_terrain import ridged_terrain  # noqa: E402

SIZE = 16385
TILE = 256


def source_tile():
    """4097² heights mirrored into a continuous 8194² tile, with a lake."""
    small = ridged_terrain(4097, seed=3, octaves=7) * 2400.0 + 100.0
    small[1500:1700, 2000:2300] = np.nan
    return np.block([[small, small[:, ::-1]], [small[::-1], small[::-1, ::-1]]]).astype(np.float32)


def rows_of(tile, y0, y1, x0=0, x1=SIZE):
    return tile[np.arange(y0, y1) % tile.shape[0]][:, np.arange(x0, x1) % tile.shape[1]]


def write_big(folder, tile):
    """The DEM as a tiled deflate GeoTIFF (tiles made one at a time) and as a raw .r32 (top row first)."""
    import tifffile

    n = -(-SIZE // TILE)

    def tiles():
        for ty in range(n):
            band = rows_of(tile, ty * TILE, min(SIZE, (ty + 1) * TILE))
            band = np.pad(band, ((0, TILE - band.shape[0]), (0, n * TILE - SIZE)))
            for tx in range(n):
                yield np.ascontiguousarray(band[:, tx * TILE:(tx + 1) * TILE])

    geo = os.path.join(folder, "dem.tif")
    directory = [1, 1, 0, 3, 1024, 0, 1, 1, 1025, 0, 1, 1, 3072, 0, 1, 32633]
    tifffile.imwrite(geo, tiles(), shape=(SIZE, SIZE), dtype="float32", tile=(TILE, TILE), compression="zlib",
                     photometric="minisblack", metadata=None,
                     extratags=[(34735, "H", len(directory), directory, True),
                                (33550, "d", 3, (30.0, 30.0, 0.0), True),
                                (33922, "d", 6, (0.0, 0.0, 0.0, 500000.0, 4600000.0, 0.0), True),
                                (42113, "s", 0, "nan", True)])
    raw = os.path.join(folder, "dem.r32")
    with open(raw, "wb") as f:
        for y0 in range(0, SIZE, 1024):
            band = rows_of(tile, y0, min(SIZE, y0 + 1024))
            np.nan_to_num(band, nan=100.0).astype("<f4").tofile(f)  # the raw baseline has no voids to fill
    return geo, raw


def measured(fn):
    tracemalloc.start()
    t = time.perf_counter()
    out = fn()
    dt = time.perf_counter() - t
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return out, dt, peak


def _status_kib(field):
    """A ``/proc/self/status`` memory field (VmRSS, VmHWM) in KiB."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    raise RuntimeError(f"no {field} in /proc/self/status")


def child(reader, path, out):
    """Read and analyse ``path`` with ``reader`` ("gdal" or "tiff") in this fresh process; the figures and the tile
    table into ``out`` (.npz)."""
    from tessera.kernels.terrain import gdal_raster

    if reader == "tiff":
        gdal_raster.why_not = lambda: "the bench's TIFF reader run"
    else:
        assert gdal_raster.available(), gdal_raster.why_not()
    before = _status_kib("VmRSS")
    t = time.perf_counter()
    hm, geo = gt.read_geotiff([path])
    table = tile_table(hm, 64, backend="numpy")
    dt = time.perf_counter() - t
    assert geo.files[0].reader == reader
    np.savez(out, ham_max=table.ham_max, h_min=table.h_min, h_max=table.h_max, seconds=dt,
             growth_mib=(_status_kib("VmHWM") - before) / 1024)


def _rchar():
    with open("/proc/self/io") as f:
        return int(next(line for line in f if line.startswith("rchar:")).split()[1])


def block_child(path, block, index, out):
    """Mesh the DEM ``path`` for a fixed camera, whole (``block`` "") or one block "c,r,C,R" of a split with the void
    index ``index`` (as a farm task does), in this fresh process; seconds, bytes read and the mesh into ``out``."""
    from tessera.kernels.common.camera import Camera
    from tessera.kernels.terrain import lod, mesh

    before, t = _rchar(), time.perf_counter()
    part = tuple(int(v) for v in block.split(",")) if block else None
    hm, _ = gt.read_geotiff([path], void_index=index or None)
    tiles = None
    if part:
        counts = tile_counts(hm.width, hm.height, 64)
        tiles = lod.block_region(part, counts)
        hm.hold(lod.block_window(part, counts, 64, (hm.height, hm.width)))  # as the terrain operator does
    table = tile_table(hm, 64, backend="numpy", tiles=tiles)
    half = 0.5 * (SIZE - 1) * hm.texel[0]
    cam = Camera.looking_at((0.0, -1.2 * half, 0.6 * half), (0.0, 0.0, 0.0), width=1920, height=1080, far=1e7)
    m = mesh.bake(hm, table, lod.select(hm, table, cam, lod.TerrainLod(), block=part))
    np.savez(out, seconds=time.perf_counter() - t, read=_rchar() - before, positions=m.positions,
             triangles=m.triangles)


def index_child(path, index, out):
    """Write the void index of ``path`` (the plan's one pass over the data) in this fresh process; seconds and bytes
    read into ``out``."""
    before, t = _rchar(), time.perf_counter()
    gt.write_void_index([path], index)
    np.savez(out, seconds=time.perf_counter() - t, read=_rchar() - before)


def compare_block_task(folder, geo):
    from tessera.kernels.common.weld import weld_triangles

    whole_out, index = os.path.join(folder, "whole.npz"), os.path.join(folder, "dem.tessera-voids")
    subprocess.run([sys.executable, __file__, "--block-child", geo, "", "", whole_out], check=True)
    w = np.load(whole_out)
    index_out = os.path.join(folder, "index.npz")
    subprocess.run([sys.executable, __file__, "--index-child", geo, index, index_out], check=True)
    ix = np.load(index_out)
    tasks = []
    for row in range(4):
        for col in range(4):
            out = os.path.join(folder, f"block{col}{row}.npz")
            subprocess.run([sys.executable, __file__, "--block-child", geo, f"{col},{row},4,4", index, out], check=True)
            tasks.append(np.load(out))
    offsets = np.cumsum([0] + [len(t["positions"]) for t in tasks])
    pos, tris, _, _ = weld_triangles(np.concatenate([t["positions"] for t in tasks]),
                                     np.concatenate([t["triangles"] + o for t, o in zip(tasks, offsets[:-1],
                                                                                         strict=True)]))

    def triangle_set(p, t):  # each triangle as its corners' bytes, rotated to start at its smallest corner
        keys = [tuple(c.tobytes() for c in tri) for tri in p[t]]
        return {min(k[i:] + k[:i] for i in range(3)) for k in keys}

    same = (len(pos) == len(w["positions"]) and len(tris) == len(w["triangles"])
            and triangle_set(pos, tris) == triangle_set(w["positions"], w["triangles"]))
    size = os.path.getsize(geo)
    reads = [float(t["read"]) / size for t in tasks]
    seconds = [float(t["seconds"]) for t in tasks]
    print(json.dumps({"case": "block_task", "map": f"{SIZE}x{SIZE} float32, tiles {TILE}², deflate, split 4x4",
                      "one_process_s": round(float(w["seconds"]), 2), "mean_task_s": round(float(np.mean(seconds)), 2),
                      "slowest_task_s": round(max(seconds), 2),
                      "time_ratio": round(max(seconds) / float(w["seconds"]), 2),
                      "void_index_s": round(float(ix["seconds"]), 2),
                      "one_process_read_of_file": round(float(w["read"]) / size, 3),
                      "largest_task_read_of_file": round(max(reads), 3),
                      "mean_task_read_of_file": round(float(np.mean(reads)), 3),
                      "void_index_read_of_file": round(float(ix["read"]) / size, 3),
                      "void_index_mib": round(os.path.getsize(index) / 2**20, 1),
                      "largest_task_triangles_share": round(max(len(t["triangles"]) for t in tasks)
                                                            / max(1, len(w["triangles"])), 3),
                      "joined_identical": bool(same)}), flush=True)


def compare_readers(folder, geo):
    runs = {}
    for reader in ("gdal", "tiff"):
        out = os.path.join(folder, f"{reader}.npz")
        subprocess.run([sys.executable, __file__, "--child", reader, geo, out], check=True)
        runs[reader] = np.load(out)
    g, t = runs["gdal"], runs["tiff"]
    same = all(np.array_equal(g[k], t[k]) for k in ("ham_max", "h_min", "h_max"))
    print(json.dumps({"case": "gdal_reader", "map": f"{SIZE}x{SIZE} float32, tiles {TILE}², deflate",
                      "gdal_s": round(float(g["seconds"]), 2), "tiff_reader_s": round(float(t["seconds"]), 2),
                      "time_ratio": round(float(g["seconds"] / t["seconds"]), 2),
                      "gdal_rss_growth_mib": round(float(g["growth_mib"]), 1),
                      "tiff_reader_rss_growth_mib": round(float(t["growth_mib"]), 1),
                      "identical_tables": same}), flush=True)


def main(only=None):
    """Every case, or only the case named ``only`` (``block_task``) after the files it needs."""
    folder = tempfile.mkdtemp(prefix="tessera-geotiff-")
    atexit.register(shutil.rmtree, folder, ignore_errors=True)
    tile = source_tile()
    geo, raw = write_big(folder, tile)
    if only == "block_task":
        compare_block_task(folder, geo)
        return

    def from_geotiff():
        hm, _ = gt.read_geotiff([geo])
        return tile_table(hm, 64, backend="numpy")

    def from_raw():
        return tile_table(hio.read_heightmap(raw, raw_size=(SIZE, SIZE)), 64, backend="numpy")

    table, t_geo, peak_geo = measured(from_geotiff)
    _, t_raw, peak_raw = measured(from_raw)
    print(json.dumps({"case": "geotiff_out_of_core", "map": f"{SIZE}x{SIZE} float32, tiles {TILE}², deflate",
                      "geotiff_mib": round(os.path.getsize(geo) / 2**20, 1),
                      "raw_r32_mib": round(os.path.getsize(raw) / 2**20, 1),
                      "float32_map_mib": SIZE * SIZE * 4 / 2**20, "geotiff_s": round(t_geo, 2),
                      "raw_memmap_s": round(t_raw, 2), "time_ratio": round(t_geo / t_raw, 2),
                      "geotiff_peak_mib": round(peak_geo / 2**20, 1), "raw_peak_mib": round(peak_raw / 2**20, 1),
                      "finite_tiles": bool(np.isfinite(table.h_min).all())}), flush=True)
    os.unlink(raw)
    compare_readers(folder, geo)
    compare_block_task(folder, geo)

    # four adjacent files of a 4097² DEM against the single file
    part = rows_of(tile, 0, 4097, 0, 4097)
    single = write_geotiff(os.path.join(folder, "one.tif"), part, nodata="nan", tile=(TILE, TILE))
    parts = []
    for i, (r0, r1) in enumerate(((0, 2049), (2049, 4097))):
        for j, (c0, c1) in enumerate(((0, 2049), (2049, 4097))):
            parts.append(write_geotiff(os.path.join(folder, f"part{i}{j}.tif"), part[r0:r1, c0:c1], nodata="nan",
                                       tile=(TILE, TILE), corner=(500000.0 + 30.0 * c0, 4600000.0 - 30.0 * r0)))
    one, t_one, _ = measured(lambda: tile_table(gt.read_geotiff([single])[0], 64, backend="numpy"))
    four, t_four, _ = measured(lambda: tile_table(gt.read_geotiff(parts)[0], 64, backend="numpy"))
    same = all(np.array_equal(getattr(one, k), getattr(four, k)) for k in ("ham_max", "h_min", "h_max", "peak_x"))
    print(json.dumps({"case": "geotiff_split", "map": "4097x4097 in 4 files", "one_file_s": round(t_one, 2),
                      "four_files_s": round(t_four, 2), "time_ratio": round(t_four / t_one, 2),
                      "identical_tables": same}), flush=True)


if __name__ == "__main__":
    if sys.argv[1:2] == ["--child"]:
        child(*sys.argv[2:5])
    elif sys.argv[1:2] == ["--block-child"]:
        block_child(*sys.argv[2:6])
    elif sys.argv[1:2] == ["--index-child"]:
        index_child(*sys.argv[2:5])
    else:
        main(sys.argv[2] if sys.argv[1:2] == ["--only"] else None)

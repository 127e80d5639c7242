"""Terrain objects' height maps and analyses, cached per object, and their baked meshes.

A terrain object stores only its settings (``Object.tessera.terrain``); the height map is read (memory-mapped
for raw files) and analysed once per source and kept here until the source settings change. The baked mesh
is written through the bridge and replaces the object's mesh data.
"""

import dataclasses
import os

import bpy

from ...kernels.common.errors import InvalidInputError
from ...kernels.common.mesh_arrays import MeshArrays
from ...kernels.terrain import geotiff, heightmap_io
from ...kernels.terrain.analysis import tile_counts, tile_table
from ...kernels.terrain.lod import block_region, block_window
from .. import bridge
from ..preferences import get_preferences
from .settings import is_elevation_file, source_key

_cache = {}  # object session_uid -> (source key, HeightMap, TileTable, GeoGrid or None, tiles analysed or None)
#: Scene custom property: the model position (x, y), CRS code and kind (1: geographic) that the scene's origin
#: stands for, set by the first georeferenced terrain, so that later ones (adjacent tiles) land beside it.
GEO_ORIGIN = "tessera_geo_origin"


def source_paths(s):
    """The files named by terrain settings ``s``: the height map, then the More Tiles in its folder."""
    path = os.path.normpath(bpy.path.abspath(s.filepath))
    folder = os.path.dirname(path)
    return [path] + [os.path.join(folder, n.strip()) for n in s.tile_files.split(";") if n.strip()]


def _unit_metres(scene):
    return scene.unit_settings.scale_length if scene.unit_settings.system != "NONE" else 1.0


def elevation_files(s):
    """The files of terrain settings ``s`` when they are elevation data read with their placement and no-data
    (`geotiff`), else None (a height-map image or raw file)."""
    if s.source == "FILE" and s.filepath and s.georeferenced and is_elevation_file(s.filepath):
        paths = source_paths(s)
        if os.path.isfile(paths[0]) and geotiff.read_geoinfo(paths[0], s.band) is not None:
            return paths
    return None


def read_source(s, scene=None, progress=None, void_index=""):
    """``(HeightMap, GeoGrid or None)`` named by terrain settings ``s`` (elevation files in the units of
    ``scene``); ``void_index``: a void index made of the same elevation files (`write_void_index`, by a farm plan),
    so the voids are not scanned. Raises `TesseraError` with what to fix."""
    paths = elevation_files(s)
    if paths is not None:
        scene = scene or bpy.context.scene
        hm, geo = geotiff.read_geotiff(paths, voids=s.voids, exaggeration=s.exaggeration,
                                       budget_bytes=get_preferences().memory_budget_bytes,
                                       unit_metres=_unit_metres(scene), progress=progress, band=s.band,
                                       void_index=void_index or None)
        return dataclasses.replace(hm, offset=s.height_offset), geo
    return _read_plain(s), None


def write_void_index(s, path, progress=None):
    """Scan the elevation files of terrain settings ``s`` (`elevation_files`) for voids once and write what the tasks
    of a farm split need to ``path`` (`geotiff.write_void_index`): the count of void samples."""
    return geotiff.write_void_index(elevation_files(s), path, voids=s.voids, progress=progress, band=s.band,
                                    budget_bytes=get_preferences().memory_budget_bytes)


def _read_plain(s):
    scale = dict(texel_size=s.texel_size, scale=s.height_scale, offset=s.height_offset)
    if s.source == "IMAGE":
        image = bpy.data.images.get(s.image_name)
        if image is None:
            raise InvalidInputError(f"No image named {s.image_name!r}: pick the height-map image")
        w, h = image.size
        if w < 2 or h < 2:
            raise InvalidInputError(f"The image {image.name!r} has no pixels (is its file missing?)")
        return heightmap_io.from_array(bridge.read_image_pixels(image), source=image.name, **scale)
    path = bpy.path.abspath(s.filepath)
    if not s.filepath:
        raise InvalidInputError("Choose a height-map file")
    raw = (s.raw_width, s.raw_height) if s.raw_width and s.raw_height else None
    return heightmap_io.read_heightmap(os.path.normpath(path), raw_size=raw, **scale)


def analysis(ob, progress=None, scene=None, block=None, void_index=""):
    """(HeightMap, TileTable) for terrain object ``ob``, read and analysed on first use or after a change.

    ``block`` (column, row, columns, rows): only that block of an even split and the ring of tiles around it are
    analysed (`lod.block_region`: what `lod.select` needs for the block), reading only their samples: one farm task.
    ``void_index``: see `read_source`."""
    s = ob.tessera.terrain
    scene = scene or bpy.context.scene
    key = (source_key(s), _unit_metres(scene))
    hit = _cache.get(ob.session_uid)
    if hit is not None and hit[0] == key:
        region = None if block is None else block_region(block, hit[2].counts)
        if hit[4] is None or hit[4] == region:  # a whole table serves every block
            return hit[1], hit[2]
        hm, geo = hit[1], hit[3]  # the same data: analysed again for another part
    else:
        half = None if progress is None else (lambda done, total: progress(done, 2 * total))
        hm, geo = read_source(s, scene, half, void_index)
    region = None
    if block is not None:
        counts = tile_counts(hm.width, hm.height, s.tile_size)
        region = block_region(block, counts)
        # the analysis, the levels and the mesh each read the region: from a file, decode it once
        hm.hold(block_window(block, counts, s.tile_size, (hm.height, hm.width)), get_preferences().memory_budget_bytes)
    rest = None if progress is None else (lambda done, total: progress(total + done, 2 * total))
    table = tile_table(hm, s.tile_size, progress=rest, tiles=region)
    _cache[ob.session_uid] = (key, hm, table, geo, region)
    return hm, table


def height_map(ob):
    """The `HeightMap` of terrain object ``ob`` (after `analysis`), or None."""
    hit = _cache.get(ob.session_uid)
    return None if hit is None else hit[1]


def georeference(ob):
    """The `geotiff.GeoGrid` of a terrain read from GeoTIFFs (after `analysis`), or None."""
    hit = _cache.get(ob.session_uid)
    return None if hit is None else hit[3]


def geo_location(scene, geo):
    """Where a georeferenced terrain's centre goes in ``scene``: ``(x, y)`` world units from the scene's geographic
    origin, or None when the scene has none yet (the terrain then sets it) or when its CRS differs (the terrain
    stays where it is put). The offset is converted at the origin's latitude for geographic data."""
    first = geo.files[0]
    origin = scene.get(GEO_ORIGIN)
    if origin is None or int(origin[2]) != first.crs or bool(origin[3]) != first.geographic:
        return None
    mx, my = geotiff.metres_per_unit(first, origin[1] if first.geographic else None)
    unit = _unit_metres(scene)
    cx, cy = geo.centre
    return (cx - origin[0]) * mx / unit, (cy - origin[1]) * my / unit


def set_geo_origin(scene, geo):
    """Make ``geo``'s centre the scene's geographic origin (when it has none)."""
    if scene.get(GEO_ORIGIN) is None:
        first = geo.files[0]
        scene[GEO_ORIGIN] = [float(geo.centre[0]), float(geo.centre[1]), float(first.crs), float(first.geographic)]


def forget(ob=None):
    """Drop cached analyses (one object's, or all of them)."""
    if ob is None:
        _cache.clear()
    else:
        _cache.pop(ob.session_uid, None)


def write_terrain_mesh(ob, mesh_name, terrain_mesh):
    """Replace ``ob``'s mesh with ``terrain_mesh`` (positions, triangles, UV map "UVMap"); keeps materials."""
    arrays = MeshArrays(terrain_mesh.positions, terrain_mesh.triangles,
                        corner_attributes={"UVMap": terrain_mesh.uvs[terrain_mesh.triangles]},
                        attribute_types={"UVMap": "FLOAT2"})
    mesh = bridge.write_mesh(mesh_name, arrays)
    old = ob.data if ob.type == "MESH" else None
    if old is not None:
        for material in old.materials:
            mesh.materials.append(material)
    if ob.type == "MESH":
        ob.data = mesh
        if old is not None and old.users == 0:
            bpy.data.meshes.remove(old)
    return mesh

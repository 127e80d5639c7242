"""Terrain objects' height maps and analyses, cached per object, and their baked meshes.

A terrain object stores only its settings (``Object.tessera.terrain``); the height map is read (memory-mapped
for raw files) and analysed once per source and kept here until the source settings change. The baked mesh
is written through the bridge and replaces the object's mesh data.
"""

import os

import bpy

from ...kernels.common.errors import InvalidInputError
from ...kernels.common.mesh_arrays import MeshArrays
from ...kernels.terrain import heightmap_io
from ...kernels.terrain.analysis import tile_table
from .. import bridge
from .settings import source_key

_cache = {}  # object session_uid -> (source key, HeightMap, TileTable)


def read_source(s):
    """The `HeightMap` named by terrain settings ``s``. Raises `TesseraError` with what to fix."""
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


def analysis(ob, progress=None):
    """(HeightMap, TileTable) for terrain object ``ob``, read and analysed on first use or after a change."""
    s = ob.tessera.terrain
    key = source_key(s)
    hit = _cache.get(ob.session_uid)
    if hit is not None and hit[0] == key:
        return hit[1], hit[2]
    hm = read_source(s)
    table = tile_table(hm, s.tile_size, progress=progress)
    _cache[ob.session_uid] = (key, hm, table)
    return hm, table


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

"""Vertex normals for the curved patches, and the hard-edge policy.

PN triangles and Phong tessellation move a point using the normals of its triangle's corners. Where a
vertex has several normals (sharp edges, custom split normals) the two triangles of an edge would build
different edge curves and the surface would crack. Two policies (`NORMAL_MODES`):

``WATERTIGHT`` (default)
    The geometry uses one shared normal per vertex: the angle-weighted mean of its corner normals.
    Shading keeps the split normals, so a closed input gives a closed output that still shades sharp.
``SPLIT``
    Each distinct corner normal gets its own vertex (`split_by_normals`), so the geometry follows the
    split normals and opens along the sharp edges; the caller reports how many edges opened.
"""

import numpy as np

from ..common.normals import unit as _unit
from ..common.tolerances import SAME_NORMAL_DOT

NORMAL_MODES = ("WATERTIGHT", "SPLIT")


def split_corners(triangles, corner_normals, vertex_normals):
    """Which corners carry a normal different from their vertex's shared normal: -> (T, 3) bool."""
    cn = _unit(np.asarray(corner_normals, np.float64))
    dots = np.einsum("tci,tci->tc", cn, vertex_normals[triangles])
    return dots < SAME_NORMAL_DOT


def split_by_normals(triangles, corner_normals, n_vertices):
    """Give every distinct (vertex, corner normal) pair its own vertex.

    triangles: (T, 3) int; corner_normals: (T, 3, 3). Normals within `SAME_NORMAL_DOT` of each other
    are treated as equal (they are quantised before comparison). Returns ``(triangles (T, 3) int32,
    source_vertex (V', ) int64, vertex_normals (V', 3) float64)``; output vertex ``i`` copies input vertex
    ``source_vertex[i]``. Vertices with a single normal keep their relative order.
    """
    cn = _unit(np.asarray(corner_normals, np.float64)).reshape(-1, 3)
    quant = np.round(cn * 1e5).astype(np.int64)
    keys = np.concatenate([triangles.reshape(-1, 1).astype(np.int64), quant], axis=1)
    uniq, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    source = uniq[:, 0]
    normals = cn[first]
    return inverse.reshape(triangles.shape).astype(np.int32), source, normals

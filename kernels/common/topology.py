"""Edge topology of triangle meshes, and the ragged-array helper the refinement is built on."""

from dataclasses import dataclass

import numpy as np

from .errors import InvalidInputError


def validate_triangles(triangles, n_vertices):
    """Check a triangle array and return it as contiguous int32.

    triangles: (T, 3) int. Raises `InvalidInputError` for indices out of range or a triangle that
    repeats a vertex (zero-area by construction, no edge structure).
    """
    tris = np.asarray(triangles)
    if tris.ndim != 2 or tris.shape[1] != 3:
        raise InvalidInputError(f"Triangles must have shape (T, 3); got {tris.shape}")
    if not np.issubdtype(tris.dtype, np.integer):
        raise InvalidInputError(f"Triangle indices must be integers; got {tris.dtype}")
    if len(tris) == 0:
        raise InvalidInputError("The mesh has no faces to tessellate")
    if tris.min() < 0 or tris.max() >= n_vertices:
        raise InvalidInputError(
            f"Triangle indices must lie in [0, {n_vertices}); found {tris.min()}..{tris.max()}"
        )
    bad = (tris[:, 0] == tris[:, 1]) | (tris[:, 1] == tris[:, 2]) | (tris[:, 2] == tris[:, 0])
    if bad.any():
        raise InvalidInputError(
            f"{int(bad.sum())} triangle(s) use the same vertex twice (first: triangle {int(np.argmax(bad))})"
        )
    return np.ascontiguousarray(tris, dtype=np.int32)


def triangle_edges(triangles):
    """Unique undirected edges of a triangle mesh.

    triangles: (T, 3) int32 (validated). Local edge ``e`` of a triangle runs from corner ``e`` to corner
    ``(e + 1) % 3``.

    Returns ``(edges, face_edges, flipped)``:
    edges: (E, 2) int32, each row ``(lo, hi)`` with ``lo < hi``, rows sorted lexicographically;
    face_edges: (T, 3) int32 edge id of each local edge;
    flipped: (T, 3) bool, True where the local edge runs from ``hi`` to ``lo``.
    """
    a = triangles.astype(np.int64)
    start = a
    end = np.roll(a, -1, axis=1)
    lo = np.minimum(start, end)
    hi = np.maximum(start, end)
    n = int(a.max()) + 1
    keys = (lo * n + hi).ravel()
    uniq, inverse = np.unique(keys, return_inverse=True)
    edges = np.stack([uniq // n, uniq % n], axis=1).astype(np.int32)
    face_edges = inverse.reshape(triangles.shape).astype(np.int32)
    return edges, face_edges, start > end


@dataclass(frozen=True)
class MeshTopology:
    """A triangle mesh's edge table, built once and carried to every step that needs it.

    triangles: (T, 3) int32, validated; n_vertices: V; edges, face_edges, flipped: as `triangle_edges` returns them.
    """

    triangles: np.ndarray
    n_vertices: int
    edges: np.ndarray
    face_edges: np.ndarray
    flipped: np.ndarray


def mesh_topology(triangles, n_vertices):
    """Validate ``triangles`` (T, 3) and build their edge table: a `MeshTopology`."""
    tris = validate_triangles(triangles, n_vertices)
    return MeshTopology(tris, int(n_vertices), *triangle_edges(tris))


def ragged(counts):
    """Flatten ``counts[i]`` items per owner ``i``.

    counts: (K,) int >= 0. Returns ``(owner, local, starts)``: owner (N,) int64 owner index of each item,
    local (N,) int64 index of the item within its owner, starts (K,) int64 offset of each owner's first item,
    where ``N = counts.sum()``.
    """
    counts = np.asarray(counts, dtype=np.int64)
    starts = np.cumsum(counts) - counts
    owner = np.repeat(np.arange(len(counts), dtype=np.int64), counts)
    local = np.arange(int(counts.sum()), dtype=np.int64) - starts[owner]
    return owner, local, starts


def group_by_class(inverse, n_classes):
    """Owners of each class, in owner order: (K,) int class per owner -> list of n_classes (k_c,) int64 arrays."""
    order = np.argsort(inverse, kind="stable")
    return np.split(order, np.cumsum(np.bincount(inverse, minlength=n_classes))[:-1])

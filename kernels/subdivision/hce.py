"""Hierarchical Colour Encoding (HCE) of [Concheiro et al.]: several colours per coarse triangle, one per normal, in a
quadtree that follows Loop's 1 -> 4 split, and their transfer to a Loop-subdivided mesh at any level.

Per coarse triangle: ``m`` extra normals N (the triangle's own normal n0 is not stored: it comes from the
geometry) and a tree of nodes in breadth-first order, each with ``m + 1`` colours E (one per normal). A node's
children are its sub-triangles in the T/L/C/R order of `loop_topology` (T = (a, m_ab, m_ca), L = (m_ab, b, m_bc),
C = (m_ab, m_bc, m_ca), R = (m_ca, m_bc, c)); the children of subdivided node x are nodes
``1 + 4 q(x) + slot``, q(x) the number of subdivided nodes before x ([Concheiro et al.], checked by the tests).

Stream layout ([Concheiro et al., correction 3]: a node carries its child bits only when it is
subdivided, which its parent's bit, or s for the root, already says):

    J = s:u8  m:u8  N:(m, 3) f32  then per node, breadth first: E:(m + 1, C) f32  [bits:u8 if subdivided]

with bits = T << 3 | L << 2 | C << 1 | R. Colour selection ([Concheiro et al., correction 2]): a sub-triangle with unit
normal n takes E[k*] of the node on its T/L/C/R path (clamped to the deepest node there is), k* =
argmax_k n_k . n over the root's normals (n0 first, so ties keep the triangle's own normal). Vertex colours are
the mean of the colours of every sub-triangle around the vertex ([Concheiro et al., correction 5], uniform weights; the
subdivided mesh is welded, so both sides of a coarse edge share each vertex's colour: no seam).
"""

import hashlib
from dataclasses import dataclass

import numpy as np

from ..common.errors import InvalidInputError
from ..common.normals import accumulate

SLOTS = "TLCR"


@dataclass
class HceTree:
    """The HCE of one coarse triangle: normals (m, 3) float32 extra normals; colours (K, m + 1, C) float32 per
    node in breadth-first order; subdivided (K,) bool."""

    normals: np.ndarray
    colours: np.ndarray
    subdivided: np.ndarray

    def first_child(self):
        """(K,) int64: index of each node's T child (its L, C, R children follow), -1 for leaves: 1 + 4 q(x)."""
        q = np.cumsum(self.subdivided) - self.subdivided
        return np.where(self.subdivided, 1 + 4 * q, -1).astype(np.int64)

    def validate(self):
        """Raise `InvalidInputError` unless the node count matches the subdivided flags (1 + 4 per subdivided
        node) and the shapes agree."""
        k = len(self.subdivided)
        if k != 1 + 4 * int(np.count_nonzero(self.subdivided)):
            split = int(np.count_nonzero(self.subdivided))
            raise InvalidInputError(f"A baked-lighting tree with {split} subdivided node(s) has {1 + 4 * split} "
                                    f"nodes, not {k}")
        if self.colours.shape[:2] != (k, len(self.normals) + 1):
            raise InvalidInputError(f"Baked-lighting colours have shape {self.colours.shape}; expected ({k}, "
                                    f"{len(self.normals) + 1}, C)")
        # breadth first: the children ranges 1 + 4 q .. 4 + 4 q tile nodes 1..K-1; each must follow its parent
        fc = self.first_child()
        if np.any((fc >= 0) & (fc <= np.arange(k))):
            raise InvalidInputError("Baked-lighting nodes are not in breadth-first order")
        return self


def encode(tree):
    """The stream J of an `HceTree` as bytes (layout in the module docstring)."""
    tree.validate()
    m = len(tree.normals)
    if m > 255:
        raise InvalidInputError(f"Baked lighting holds at most 255 extra normals per triangle; got {m}")
    parts = [np.array([int(tree.subdivided[0]), m], np.uint8).tobytes(),
             np.ascontiguousarray(tree.normals, "<f4").tobytes()]
    fc = tree.first_child()
    for node in range(len(tree.subdivided)):
        parts.append(np.ascontiguousarray(tree.colours[node], "<f4").tobytes())
        if tree.subdivided[node]:
            kids = tree.subdivided[fc[node] : fc[node] + 4]
            parts.append(bytes([int(kids[0]) << 3 | int(kids[1]) << 2 | int(kids[2]) << 1 | int(kids[3])]))
    return b"".join(parts)


def decode(stream, channels):
    """An `HceTree` from the bytes of `encode` with ``channels`` colour channels; raises `InvalidInputError` on a
    stream that is short, long or inconsistent."""
    buf = memoryview(bytes(stream))
    if len(buf) < 2:
        raise InvalidInputError("The baked-lighting data is too short: it needs at least its two header bytes")
    s, m = buf[0], buf[1]
    if s > 1:
        raise InvalidInputError(f"The baked-lighting data is damaged: its start bit is {s}, not 0 or 1")
    at = 2
    need = 12 * m
    if len(buf) < at + need:
        raise InvalidInputError("The baked-lighting data ends inside its normals")
    normals = np.frombuffer(buf[at : at + need], "<f4").reshape(m, 3).astype(np.float32)
    at += need
    size = 4 * (m + 1) * channels
    colours, subdivided = [], [bool(s)]
    node = 0
    while node < len(subdivided):
        if len(buf) < at + size:
            raise InvalidInputError(f"The baked-lighting data ends inside node {node}")
        colours.append(np.frombuffer(buf[at : at + size], "<f4").reshape(m + 1, channels))
        at += size
        if subdivided[node]:
            if len(buf) < at + 1:
                raise InvalidInputError(f"The baked-lighting data ends before node {node}'s child bits")
            bits = buf[at]
            if bits > 15:
                raise InvalidInputError(f"The baked-lighting data is damaged: child bits {bits} do not fit four "
                                        "children")
            subdivided += [bool(bits >> 3 & 1), bool(bits >> 2 & 1), bool(bits >> 1 & 1), bool(bits & 1)]
            at += 1
        node += 1
    if at != len(buf):
        raise InvalidInputError(f"The baked-lighting data has {len(buf) - at} byte(s) after its last node")
    return HceTree(normals, np.array(colours, np.float32).reshape(-1, m + 1, channels), np.array(subdivided))


@dataclass
class HceMesh:
    """The HCE trees of a mesh's F coarse triangles, packed for lookups.

    normals: (F, M, 3) float32 extra normals, padded with zeros (never chosen) to M = the largest m;
    n_normals: (F,) int64 each triangle's m; node_start: (F + 1,) int64 where each triangle's nodes begin;
    colours: (N, M + 1, C) float32; first_child: (N,) int64 global index of each node's T child, -1 for leaves.
    """

    normals: np.ndarray
    n_normals: np.ndarray
    node_start: np.ndarray
    colours: np.ndarray
    first_child: np.ndarray

    @classmethod
    def pack(cls, trees):
        trees = [t.validate() for t in trees]
        if not trees:
            raise InvalidInputError("Baked lighting needs at least one triangle")
        m_max = max(len(t.normals) for t in trees)
        channels = trees[0].colours.shape[2]
        counts = np.array([len(t.subdivided) for t in trees], np.int64)
        start = np.concatenate([[0], np.cumsum(counts)])
        normals = np.zeros((len(trees), m_max, 3), np.float32)
        colours = np.zeros((start[-1], m_max + 1, channels), np.float32)
        first = np.empty(start[-1], np.int64)
        for i, t in enumerate(trees):
            m = len(t.normals)
            normals[i, :m] = t.normals
            colours[start[i] : start[i + 1], : m + 1] = t.colours
            fc = t.first_child()
            first[start[i] : start[i + 1]] = np.where(fc >= 0, fc + start[i], -1)
        return cls(normals, np.array([len(t.normals) for t in trees], np.int64), start, colours, first)


def path_nodes(hce, levels, depth=None):
    """The node each sub-triangle of a level-``levels`` Loop result reads: (F * 4^levels,) int64 global node ids.

    Sub-face j of coarse triangle ``j >> 2 levels`` follows its T/L/C/R digits from the root down, stopping at a
    leaf (deeper trees than ``depth`` (default ``levels``) are read at ``depth``)."""
    n_coarse = len(hce.node_start) - 1
    faces = np.arange(n_coarse << (2 * levels), dtype=np.int64)
    node = hce.node_start[faces >> (2 * levels)].copy()
    depth = levels if depth is None else min(depth, levels)
    for d in range(1, depth + 1):
        slot = (faces >> (2 * (levels - d))) & 3
        child = hce.first_child[node]
        node = np.where(child >= 0, child + slot, node)
    return node


def select_colours(hce, levels, root_normals, face_normals):
    """Per sub-triangle colour (F * 4^levels, C) float32: E[k*] of its path node, k* = argmax over n0 (the coarse
    triangle's own normal, root_normals (F, 3)) and its extra normals of the dot with face_normals
    (F * 4^levels, 3) unit; ties keep the lowest k."""
    nodes = path_nodes(hce, levels)
    coarse = np.arange(len(nodes), dtype=np.int64) >> (2 * levels)
    cand = np.concatenate([np.asarray(root_normals, np.float64)[:, None], hce.normals.astype(np.float64)], axis=1)
    dots = np.einsum("fkc,fc->fk", cand[coarse], np.asarray(face_normals, np.float64))
    m_max = hce.normals.shape[1]
    dots[np.arange(m_max + 1)[None, :] > hce.n_normals[coarse][:, None]] = -np.inf  # padding is never chosen
    k = np.argmax(dots, axis=1)
    return hce.colours[nodes, k]


def vertex_colours(triangles, face_colours, n_vertices):
    """Mean of the colours (F, C) of the faces around each vertex: (V, C) float32 (uniform weights, in face order)."""
    corner = np.repeat(np.asarray(face_colours, np.float64)[:, None, :], 3, axis=1)
    counts = np.bincount(np.asarray(triangles).ravel(), minlength=n_vertices)
    return (accumulate(triangles, corner, n_vertices) / np.maximum(counts, 1)[:, None]).astype(np.float32)


def pick_normals(leaf_normals, root_normals, m, cos_spread=0.9):
    """Up to ``m`` extra normals per coarse triangle, farthest first: the leaf normal least like the set so far,
    while some leaf's best dot with the set is below ``cos_spread``. leaf_normals (F, L, 3) unit, root_normals
    (F, 3) unit -> (normals (F, m, 3) float32 zero-padded, counts (F,) int64)."""
    n_f = len(leaf_normals)
    chosen = np.zeros((n_f, m, 3))
    counts = np.zeros(n_f, np.int64)
    best = np.einsum("flc,fc->fl", leaf_normals, root_normals)
    for k in range(m):
        far = np.argmin(best, axis=1)
        need = best[np.arange(n_f), far] < cos_spread
        if not need.any():
            break
        pick = leaf_normals[np.arange(n_f), far]
        chosen[need, k] = pick[need]
        counts[need] += 1
        best = np.where(need[:, None], np.maximum(best, np.einsum("flc,fc->fl", leaf_normals, pick)), best)
    return chosen.astype(np.float32), counts


def encode_samples(leaf_colours, leaf_normals, root_normals, m=4, tolerance=1.0 / 255, cos_spread=0.9):
    """HCE trees from colours sampled at every sub-triangle of depth D (what a bake gives).

    leaf_colours: (F, 4^D, C) float; leaf_normals: (F, 4^D, 3) unit normals of those sub-triangles; both in
    Loop's sub-face order (path digits T/L/C/R from the root); root_normals: (F, 3) unit. Extra normals come
    from `pick_normals`; each leaf uses the one `select_colours` would pick. A node's colour for normal k is the
    mean of its leaves that pick k (of all its leaves where none does); a node is subdivided while some leaf
    under it differs from its node's colour by more than ``tolerance`` (any channel), so decoding at depth D is
    within ``tolerance`` of the samples. Returns a list of F `HceTree`.
    """
    colours = np.asarray(leaf_colours, np.float64)
    normals = np.asarray(leaf_normals, np.float64)
    n_f, n_leaves, channels = colours.shape
    depth = int(round(np.log(n_leaves) / np.log(4)))
    if 4**depth != n_leaves:
        raise InvalidInputError(f"Baked-lighting samples need 4^Depth sub-triangles per triangle; got {n_leaves}")
    extra, counts = pick_normals(normals, np.asarray(root_normals, np.float64), m, cos_spread)
    cand = np.concatenate([np.asarray(root_normals, np.float64)[:, None], extra.astype(np.float64)], axis=1)
    dots = np.einsum("fkc,flc->flk", cand, normals)
    dots[np.broadcast_to(np.arange(m + 1)[None, None, :] > counts[:, None, None], dots.shape)] = -np.inf
    pick = np.argmax(dots, axis=2)  # (F, L)
    onehot = (pick[..., None] == np.arange(m + 1)).astype(np.float64)  # (F, L, m + 1)

    node_colours, split = [], []
    for d in range(depth + 1):
        size = 4 ** (depth - d)
        oh = onehot.reshape(n_f, 4**d, size, m + 1)
        col = colours.reshape(n_f, 4**d, size, channels)
        n_k = oh.sum(axis=2)  # (F, nodes, m + 1)
        sums = np.einsum("fnlk,fnlc->fnkc", oh, col)
        mean_all = col.mean(axis=2)[:, :, None, :]
        e = np.where(n_k[..., None] > 0, sums / np.maximum(n_k, 1)[..., None], mean_all)
        node_colours.append(e.astype(np.float32))
        if d < depth:  # the colour each leaf would get from this node
            got = np.take_along_axis(e[:, :, None, :, :], pick.reshape(n_f, 4**d, size)[..., None, None], axis=3)
            split.append(np.abs(got[:, :, :, 0, :] - col).max(axis=(2, 3)) > tolerance)
        else:
            split.append(np.zeros((n_f, 4**d), bool))

    trees = []
    for f in range(n_f):
        exists = np.ones(1, bool)
        flags, cols = [], []
        for d in range(depth + 1):
            at = np.flatnonzero(exists)
            sub = split[d][f, at]
            flags.append(sub)
            cols.append(node_colours[d][f, at, : counts[f] + 1])
            exists = np.repeat(np.zeros(4**d, bool), 4) if d == depth else np.repeat(
                np.isin(np.arange(4**d), at[sub]), 4)
            if not exists.any():
                break
        trees.append(HceTree(extra[f, : counts[f]], np.concatenate(cols), np.concatenate(flags)))
    return trees


MAGIC = b"TESSERA-HCE1"


def topology_key(triangles):
    """A short hash of a coarse triangle list (F, 3): the HCE belongs to exactly these triangles."""
    return hashlib.sha256(np.ascontiguousarray(triangles, "<i4").tobytes()).digest()[:16]


def pack_container(trees, triangles, channels):
    """All trees of a mesh as one bytes object to store with it: magic, channels, F, the triangles' key, the F + 1
    stream offsets (uint64), then the `encode` streams."""
    streams = [encode(t) for t in trees]
    offsets = np.concatenate([[0], np.cumsum([len(s) for s in streams])]).astype("<u8")
    head = MAGIC + np.array([channels, len(trees)], "<u4").tobytes() + topology_key(triangles)
    return head + offsets.tobytes() + b"".join(streams)


def unpack_container(blob, triangles):
    """`HceMesh` from `pack_container` bytes, for these coarse triangles; raises `InvalidInputError` when the
    bytes are not an HCE or belong to other triangles (the mesh was edited after the bake)."""
    if not isinstance(blob, bytes | bytearray | memoryview):
        raise InvalidInputError(f"The mesh's stored baked lighting holds a {type(blob).__name__}, not the bytes a bake "
                                "writes: delete its tessera_hce property, or bake the lighting again")
    blob = bytes(blob)
    head = len(MAGIC) + 8 + 16
    if len(blob) < head or not blob.startswith(MAGIC):
        raise InvalidInputError("The stored baked lighting is not in a format this Tessera reads (or was written by a "
                                "newer Tessera)")
    channels, n_faces = (int(x) for x in np.frombuffer(blob[len(MAGIC) : len(MAGIC) + 8], "<u4"))
    if n_faces != len(triangles) or blob[len(MAGIC) + 8 : head] != topology_key(triangles):
        raise InvalidInputError("The baked lighting belongs to other faces than these (the mesh was edited after "
                                "the bake, or modifiers change its faces): bake the lighting again")
    end = head + 8 * (n_faces + 1)
    offsets = np.frombuffer(blob[head:end], "<u8").astype(np.int64)
    if len(blob) != end + offsets[-1]:
        raise InvalidInputError("The stored baked lighting is truncated")
    data = blob[end:]
    return HceMesh.pack([decode(data[offsets[i] : offsets[i + 1]], channels) for i in range(n_faces)])

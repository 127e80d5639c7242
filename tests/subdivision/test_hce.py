"""The HCE codec and colour transfer ([Concheiro et al.]): the worked example, round trips, the O(1) child index,
T/L/C/R paths on Loop faces, colour selection and seam-free vertex colours."""

import struct

import numpy as np
import pytest
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.common.normals import face_unit_normals
from tessera.kernels.subdivision.hce import (
    HceMesh,
    HceTree,
    decode,
    encode,
    path_nodes,
    select_colours,
    vertex_colours,
)
from tessera.kernels.subdivision.loop import loop_subdivide
from tessera.tools.generators import random_irregular_closed

pytestmark = pytest.mark.usefixtures("numpy_reference")  # the numpy reference; OpenCL is compared elsewhere


def random_tree(rng, depth, m, channels=3, p=0.6):
    """A random breadth-first tree no deeper than ``depth``, with its nodes' depths and parents."""
    subdivided, depths, parent = [], [0], [-1]
    node = 0
    while node < len(depths):
        split = depths[node] < depth and rng.random() < (1.0 if node == 0 and depth > 0 else p)
        subdivided.append(split)
        if split:
            depths += [depths[node] + 1] * 4
            parent += [node] * 4
        node += 1
    k = len(subdivided)
    tree = HceTree(rng.normal(size=(m, 3)).astype(np.float32), rng.random((k, m + 1, channels)).astype(np.float32),
                   np.array(subdivided))
    return tree, np.array(depths), np.array(parent)


def test_worked_example():
    """Root subdivided, only its L child subdivided, m = 1: J = 1 | 1 | n1 | E0[0100] | E1 | E2[0000] | E3 | E4 |
    E5..E8, and node 2's children are 5..8."""
    flags = np.array([1, 0, 1, 0, 0, 0, 0, 0, 0], bool)
    colours = np.arange(9 * 2 * 3, dtype=np.float32).reshape(9, 2, 3)
    n1 = np.array([[0.0, 0.6, 0.8]], np.float32)
    tree = HceTree(n1, colours, flags)
    assert list(tree.first_child()) == [1, -1, 5, -1, -1, -1, -1, -1, -1]
    e = [colours[k].astype("<f4").tobytes() for k in range(9)]
    expect = bytes([1, 1]) + struct.pack("<3f", 0.0, 0.6, 0.8) + e[0] + bytes([0b0100]) + e[1] + e[2] + bytes([0]) \
        + e[3] + e[4] + b"".join(e[5:])
    assert encode(tree) == expect
    back = decode(expect, 3)
    assert np.array_equal(back.subdivided, flags) and np.array_equal(back.colours, colours)


@pytest.mark.parametrize("seed", range(12))
def test_round_trip_and_child_index(seed):
    rng = np.random.default_rng(seed)
    depth, m = int(rng.integers(0, 7)), int(rng.integers(0, 9))
    tree, depths, parent = random_tree(rng, depth, m, channels=int(rng.integers(1, 5)))
    back = decode(encode(tree), tree.colours.shape[2])
    assert np.array_equal(back.normals, tree.normals) and np.array_equal(back.colours, tree.colours)
    assert np.array_equal(back.subdivided, tree.subdivided)
    # 1 + 4 q(x) + slot is where the breadth-first walk put each child
    fc = tree.first_child()
    for x in np.flatnonzero(tree.subdivided):
        assert np.array_equal(np.flatnonzero(parent == x), fc[x] + np.arange(4))
    assert np.all(np.diff(depths) >= 0)  # breadth first


@pytest.mark.parametrize("stream, words", [
    (b"", ["two header bytes"]), (bytes([2, 0]) + bytes(12), ["start bit"]), (bytes([0, 1]) + bytes(8), ["normals"]),
    (bytes([0, 0]) + bytes(8), ["node 0"]), (bytes([1, 0]) + bytes(12), ["child bits"]),
    (bytes([1, 0]) + bytes(12) + bytes([16]), ["do not fit four children"]),
    (bytes([0, 0]) + bytes(13), ["after its last node"]),
])
def test_bad_streams_are_refused(stream, words):
    with pytest.raises(InvalidInputError) as err:
        decode(stream, 3)
    for w in words:
        assert w in str(err.value)


def test_inconsistent_trees_are_refused():
    with pytest.raises(InvalidInputError, match="nodes"):
        HceTree(np.zeros((0, 3)), np.zeros((4, 1, 3)), np.array([1, 0, 0, 0], bool)).validate()


def test_paths_follow_loop_faces_and_clamp_at_leaves():
    """Sub-face j of a level-L Loop result reads the node of its T/L/C/R digits; shallower trees clamp to the
    leaf, deeper ones are read at the render level (internal nodes' own colours)."""
    rng = np.random.default_rng(4)
    trees, walks = [], []
    for _ in range(6):
        tree, _, _ = random_tree(rng, 3, 1, p=0.5)
        trees.append(tree)
    hce = HceMesh.pack(trees)
    for levels in (1, 2, 3, 4):
        nodes = path_nodes(hce, levels)
        assert len(nodes) == 6 * 4**levels
        for j in rng.choice(len(nodes), 40):
            t = j >> (2 * levels)
            fc = trees[t].first_child()
            node = 0
            for d in range(1, levels + 1):
                if fc[node] < 0:
                    break
                node = fc[node] + ((j >> (2 * (levels - d))) & 3)
            walks.append(node)
            assert nodes[j] == hce.node_start[t] + node


def test_colour_selection_takes_the_closest_normal_ties_to_the_lowest():
    tree = HceTree(np.array([[1, 0, 0], [0, 1, 0]], np.float32), np.arange(3 * 3, dtype=np.float32).reshape(1, 3, 3),
                   np.array([False]))
    hce = HceMesh.pack([tree])
    root = np.array([[0.0, 0.0, 1.0]])
    faces = np.array([[0.9, 0.1, 0.1], [0.1, 0.9, 0.0], [0, 0, 1], [1, 1, 0], [1, 0, 1]], float)
    faces /= np.linalg.norm(faces, axis=1, keepdims=True)
    got = [select_colours(hce, 0, root, f[None])[0, 0] for f in faces]
    assert got == [3.0, 6.0, 0.0, 3.0, 0.0]  # k = 1, 2, 0, tie 1/2 -> 1, tie 0/1 -> 0
    # padding of a smaller normal set is never chosen
    small = HceTree(np.zeros((0, 3), np.float32), np.full((1, 1, 3), 7.0, np.float32), np.array([False]))
    packed = HceMesh.pack([tree, small])
    out = select_colours(packed, 0, np.array([[0, 0, 1.0], [0, 0, -1.0]]), np.array([[1.0, 0, 0], [1.0, 0, 0]]))
    assert out[1, 0] == 7.0


def test_vertex_colours_average_every_incident_sub_triangle():
    v, f = random_irregular_closed(8)
    rng = np.random.default_rng(2)
    trees = [random_tree(rng, 2, int(rng.integers(0, 3)))[0] for _ in range(len(f))]
    hce = HceMesh.pack(trees)
    r = loop_subdivide(v, f, 2, dtype=np.float64)
    faces = face_unit_normals(r.positions, r.triangles)
    colours = select_colours(hce, 2, face_unit_normals(v, f), faces)
    per_vertex = vertex_colours(r.triangles, colours, len(r.positions))
    # an explicit average over the faces around a few vertices, coarse-edge vertices (from two coarse faces) included
    on_edges = np.flatnonzero(r.coarse_edge() >= 0)
    for vid in np.unique(r.edges[on_edges[::37]].ravel()):
        around = np.flatnonzero((r.triangles == vid).any(axis=1))
        assert len(np.unique(r.coarse_face()[around])) >= 2
        assert np.allclose(per_vertex[vid], colours[around].mean(axis=0), atol=1e-6)


def leaf_samples(v, f, depth, colour_fn):
    """Loop-subdivide to ``depth`` and sample a colour per sub-triangle: (colours (F, 4^D, C), normals, result)."""
    r = loop_subdivide(v, f, depth, dtype=np.float64)
    normals = face_unit_normals(r.positions, r.triangles)
    centres = r.positions[r.triangles].mean(axis=1)
    colours = colour_fn(centres, normals)
    return colours.reshape(len(f), 4**depth, -1), normals.reshape(len(f), 4**depth, 3), r


def test_encoded_samples_decode_within_the_tolerance():
    from tessera.kernels.subdivision.hce import encode_samples

    v, f = random_irregular_closed(1)
    light = np.array([0.3, 0.5, 0.81])

    def shade(centres, normals):  # diffuse light plus a colour varying over the surface
        lambert = np.clip(normals @ light, 0, None)[:, None]
        return np.concatenate([lambert * (0.5 + 0.5 * np.sin(3 * centres)), np.ones((len(centres), 1))], axis=1)

    cols, normals, r = leaf_samples(v, f, 3, shade)
    roots = face_unit_normals(v, f)
    for tol in (0.0, 0.02, 0.2):
        trees = encode_samples(cols, normals, roots, m=4, tolerance=tol)
        hce = HceMesh.pack(trees)
        got = select_colours(hce, 3, roots, normals.reshape(-1, 3))
        assert np.abs(got - cols.reshape(-1, 4)).max() <= tol + 1e-6
        sizes = [len(t.subdivided) for t in trees]
        if tol == 0.0:
            assert max(sizes) == 85  # full depth 3 where the colours vary
        if tol == 0.2:
            assert np.mean(sizes) < 85  # coarser where they do not
    flat = encode_samples(np.full((len(f), 16, 3), 0.25), normals[:, :16], roots, tolerance=0.0)
    assert all(len(t.subdivided) == 1 for t in flat)  # a uniform colour is one node


def test_container_round_trip_and_stale_topology():
    from tessera.kernels.subdivision.hce import pack_container, unpack_container

    rng = np.random.default_rng(3)
    v, f = random_irregular_closed(2)
    trees = [random_tree(rng, 3, int(rng.integers(0, 4)), channels=4)[0] for _ in range(len(f))]
    blob = pack_container(trees, f, 4)
    hce = unpack_container(blob, f)
    ref = HceMesh.pack(trees)
    for name in ("normals", "n_normals", "node_start", "colours", "first_child"):
        assert np.array_equal(getattr(hce, name), getattr(ref, name)), name
    with pytest.raises(InvalidInputError, match="bake the lighting again"):
        unpack_container(blob, f[::-1])
    with pytest.raises(InvalidInputError, match="truncated"):
        unpack_container(blob[:-1], f)
    with pytest.raises(InvalidInputError, match="not in a format this Tessera reads"):
        unpack_container(b"junk", f)

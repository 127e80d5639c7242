"""Wire-mesh edges to polylines (kernels.tubes.edge_chains)."""

import numpy as np
import pytest
from tessera.kernels.common.errors import InvalidInputError
from tessera.kernels.tubes.edge_chains import chains_from_edges


def as_sets(lines, ids):
    """Each chain as (cyclic, tuple of vertex ids) normalised for direction (and rotation for loops)."""
    out = set()
    for c in range(lines.n_curves):
        v = list(ids[lines.offsets[c]:lines.offsets[c + 1]])
        if lines.cyclic[c]:
            k = v.index(min(v))
            v = v[k:] + v[:k]
            v = min(v, [v[0]] + v[1:][::-1])
        else:
            v = min(v, v[::-1])
        out.add((bool(lines.cyclic[c]), tuple(int(x) for x in v)))
    return out


def test_lines_loops_and_junctions():
    rng = np.random.default_rng(0)
    edges = [(0, 1), (1, 2), (2, 3),  # open line 0-1-2-3
             (10, 11), (11, 12), (12, 13), (13, 10),  # a loop
             (20, 21), (21, 22), (21, 23), (23, 24)]  # a Y: junction at 21
    edges = np.array(edges)[rng.permutation(11)]
    flip = rng.random(11) < 0.5
    edges[flip] = edges[flip][:, ::-1]
    pos = rng.normal(size=(25, 3))
    lines, ids = chains_from_edges(pos, edges)
    assert as_sets(lines, ids) == {
        (False, (0, 1, 2, 3)), (True, (10, 11, 12, 13)), (False, (20, 21)), (False, (21, 22)),
        (False, (21, 23, 24)),
    }
    assert np.allclose(lines.points, pos[ids])


def test_a_long_chain_in_random_order():
    n = 5000
    rng = np.random.default_rng(1)
    edges = np.stack((np.arange(n - 1), np.arange(1, n)), axis=1)[rng.permutation(n - 1)]
    lines, ids = chains_from_edges(rng.normal(size=(n, 3)), edges)
    assert lines.n_curves == 1 and (list(ids) == list(range(n)) or list(ids) == list(range(n))[::-1])


def test_no_edges_is_an_error():
    with pytest.raises(InvalidInputError, match="no edges"):
        chains_from_edges(np.zeros((3, 3)), np.zeros((0, 2), int))

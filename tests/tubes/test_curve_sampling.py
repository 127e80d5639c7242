"""Evaluated curve wire meshes back to splines (`kernels.tubes.curve_sampling`)."""

import numpy as np
from tessera.kernels.tubes.curve_sampling import spread_over_points, wire_runs


def _wire(counts, cyclic):
    """The wire mesh Blender evaluates for splines of ``counts`` points (cyclic ones closed by one edge)."""
    edges, start = [], 0
    for n, closed in zip(counts, cyclic, strict=True):
        edges += [(start + i, start + i + 1) for i in range(n - 1)]
        if closed:
            edges.append((start + n - 1, start))
        start += n
    return start, np.array(edges, np.int32).reshape(-1, 2)


def test_runs_and_closing_edges_are_found():
    counts, cyclic = [4, 3, 5, 2], [False, True, True, False]
    n, edges = _wire(counts, cyclic)
    got_counts, got_cyclic = wire_runs(n, edges[::-1])  # edge order does not matter
    assert got_counts.tolist() == counts and got_cyclic.tolist() == cyclic


def test_single_points_are_runs_of_their_own():
    n, edges = _wire([1, 3, 1], [False, False, False])
    counts, cyclic = wire_runs(n, edges)
    assert counts.tolist() == [1, 3, 1] and not cyclic.any()


def test_spread_hits_the_control_values_and_interpolates_linearly():
    values = np.array([1.0, 3.0, 2.0])
    open_ = spread_over_points(values, 5, cyclic=False)  # points at control 0, 0.5, 1, 1.5, 2
    assert np.allclose(open_, [1.0, 2.0, 3.0, 2.5, 2.0])
    closed = spread_over_points(values, 6, cyclic=True)  # the last span runs back to the first value
    assert np.allclose(closed, [1.0, 2.0, 3.0, 2.5, 2.0, 1.5])
    assert np.array_equal(spread_over_points(np.array([0.7]), 4, cyclic=True), np.full(4, 0.7))
    assert np.array_equal(spread_over_points(values, 1, cyclic=False), [1.0])

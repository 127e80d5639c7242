"""One-triangle patterns against the hardware tessellator's counts ([Nellmedin 2014, ch. 2], [Khronos]; measured on
llvmpipe)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from tessera.kernels.tessellation.refine import refine, refinement_counts, single_triangle_levels, triangle_count

# (outer (OL0, OL1, OL2), inner, triangles, unique vertices), equal spacing.
DIGEST_TABLE = [
    ((1, 1, 1), 1, 1, 3),
    ((2, 2, 2), 2, 6, 7),
    ((3, 3, 3), 3, 13, 12),
    ((4, 4, 4), 4, 24, 19),
    ((5, 5, 5), 5, 37, 27),
    ((7, 7, 7), 7, 73, 48),
    ((16, 16, 16), 16, 384, 217),
    ((64, 64, 64), 64, 6144, 3169),
    ((7, 1, 1), 1, 9, 10),
    ((7, 7, 7), 1, 21, 22),
    ((7, 7, 7), 2, 21, 22),
    ((7, 7, 7), 5, 43, 33),
    ((1, 1, 1), 16, 339, 172),
    ((1, 1, 1), 5, 25, 15),
    ((2, 5, 9), 4, 28, 23),
]


def pattern(outer, inner, spacing="EQUAL"):
    return refine(*single_triangle_levels(outer, inner), spacing=spacing)


def parametric_areas(ref):
    """Signed area of every output triangle in barycentric (u, v) space, times 2."""
    b = ref.corner_bary
    return (b[:, 1, 0] - b[:, 0, 0]) * (b[:, 2, 1] - b[:, 0, 1]) - (b[:, 2, 0] - b[:, 0, 0]) * (b[:, 1, 1] - b[:, 0, 1])


@pytest.mark.parametrize("outer, inner, n_tris, n_verts", DIGEST_TABLE)
def test_counts_match_the_hardware_tessellator(outer, inner, n_tris, n_verts):
    ref = pattern(outer, inner)
    assert len(ref.triangles) == n_tris
    assert ref.n_vertices == n_verts
    assert len(np.unique(ref.triangles)) == n_verts  # every vertex is used
    assert refinement_counts(*single_triangle_levels(outer, inner)) == (n_verts, n_tris)
    assert triangle_count(outer, inner) == n_tris


@pytest.mark.parametrize("n", [2, 3, 4, 5, 7, 16, 64])
def test_uniform_level_gives_floor_three_n_squared_over_two(n):
    assert triangle_count((n, n, n), n) == (3 * n * n) // 2


@pytest.mark.parametrize("outer, inner, n_tris", [((4, 4, 4), 3, 24), ((5, 5, 5), 5, 54)])
def test_fractional_even_counts(outer, inner, n_tris):
    # [Nellmedin 2014, Fig. 2.13], "Even" column (measured on llvmpipe).
    assert len(pattern(outer, inner, "FRACTIONAL_EVEN").triangles) == n_tris


levels = st.floats(1.0, 64.0)


@settings(max_examples=60, deadline=None)
@given(levels, levels, levels, levels, st.sampled_from(["EQUAL", "FRACTIONAL_EVEN"]))
def test_pattern_tiles_the_triangle(a, b, c, inner, spacing):
    """Every sub-triangle is counter-clockwise and their areas add up to the whole: a valid tiling."""
    ref = pattern((a, b, c), inner, spacing)
    area = parametric_areas(ref)
    assert np.all(area > 0)
    assert abs(area.sum() - 1.0) < 1e-9
    # Euler for a triangulated disk: T = 2V - B - 2.
    n_boundary = ref.n_corners + len(ref.edge_point_edge)
    assert len(ref.triangles) == 2 * ref.n_vertices - n_boundary - 2


def test_levels_map_to_opengl_edges():
    # OL0 is the edge v1-v2, OL1 is v2-v0, OL2 is v0-v1 ([Nellmedin 2014, §5.5.3]).
    ref = pattern((5, 1, 1), 1)
    on_edge = ref.edges[ref.edge_point_edge]
    assert len(on_edge) == 4 and np.all(on_edge == [1, 2])

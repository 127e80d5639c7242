"""The live nailboard in a real Blender window (scenario ``nailboard``), on OpenGL and Vulkan: the board is drawn
where Blender draws the object, instead of it; hiding the object hides the board; a redraw of an unchanged view
makes no pre-warp. (What a redraw costs the main thread is measured there and reported by the bench, not
asserted.)"""

import pytest
from test_window_tessellation import MASK_BAR
from window_tier import assert_no_traceback, run_scenario, scenario_fixture, window_blender  # noqa: F401 -- fixtures

pytestmark = pytest.mark.window


nailboard = scenario_fixture("nailboard")


def test_the_board_arrives_and_is_drawn_where_the_object_is(nailboard):
    r, _, out = nailboard
    assert r["board_ready"], f"no board after {r['first_board_s']:.0f} s ({out})"
    assert r["board_union_tiles"] > 1000
    assert r["board_vs_object_tiles"] <= MASK_BAR, f"the board covers other tiles than the object ({out})"


def test_hiding_the_object_hides_its_board(nailboard):
    r, _, _ = nailboard
    assert r["hidden_board_pixels"] == 0


def test_a_redraw_of_the_same_view_makes_no_prewarp(nailboard):
    r, _, _ = nailboard
    assert r["prewarps_per_redraw_same_view"] == 0
    assert r["prewarps_while_orbiting"] >= 1, "moving the eye should ask for a new pre-warp (the count can fail)"


def test_no_traceback(nailboard):
    assert_no_traceback(nailboard[1])

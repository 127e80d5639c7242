"""The displacement brush in a real Blender window (scenario ``brush``), on OpenGL and Vulkan: picked as a tool, its
ring under the cursor and nowhere else (none left where a stroke began), a dragged stroke paints the map."""

import pytest
from window_tier import assert_no_traceback, run_scenario, scenario_fixture, window_blender  # noqa: F401 -- fixtures

pytestmark = pytest.mark.window


brush = scenario_fixture("brush")


def test_the_tool_is_picked_and_a_stroke_paints(brush):
    r, _, _ = brush
    assert r["tool"] == "tessera.displacement_brush"
    assert r["map_changed_texels"] > 100


def test_one_ring_under_the_cursor_and_none_where_the_stroke_began(brush):
    r, _, out = brush
    assert r["hover_ring_at_cursor"] > 100, f"no ring while hovering ({out})"
    assert r["mid_stroke_ring_at_cursor"] > 100
    assert r["mid_stroke_ring_at_start"] == 0, f"a stale ring stays where the stroke began ({out})"
    assert r["after_ring_at_start"] == 0 and r["after_ring_at_end"] == 0
    assert r["after_ring_at_cursor"] > 100


def test_no_traceback(brush):
    assert_no_traceback(brush[1])

"""Selection outlines of previews in a real Blender window (scenario ``outlines``), on OpenGL and Vulkan: a selected
object whose preview is drawn instead of it shows the outline Blender draws around its applied result: in the
active and the selected colour, faint behind another object, for tessellation, Loop, tubes, terrain and the live
nailboard. (Before, the preview hid the object's geometry from Blender's overlay: no outline at all.)"""

import pytest
from window_tier import assert_no_traceback, run_scenario, scenario_fixture, window_blender  # noqa: F401 -- fixtures

pytestmark = pytest.mark.window

CASES = ("tessellation", "tessellation_selected", "tessellation_behind", "loop", "tubes", "terrain", "board")
#: Of the 8-pixel tiles either outline covers, at most this share is covered by one only. Blender smooths its
#: outline (its overlay's anti-aliasing), so the two differ by a pixel along the line, not by tiles.
OUTLINE_TILE_BAR = 0.15


outlines = scenario_fixture("outlines")


@pytest.mark.parametrize("case", CASES)
def test_a_selected_preview_has_the_outline_of_its_applied_result(outlines, case):
    r, _, out = outlines
    drawn, applied = r[f"{case}_outline_preview"], r[f"{case}_outline_applied"]
    assert applied > 1000, f"Blender's outline of the applied {case} should be seen ({out})"
    assert 0.5 * applied <= drawn <= 1.5 * applied, (
        f"the {case} preview's outline has {drawn} pixels, Blender's of the applied result {applied} ({out})")
    assert r[f"{case}_outline_mismatch"] <= OUTLINE_TILE_BAR, (
        f"{r[f'{case}_outline_mismatch']:.1%} of the outline's tiles differ ({r['gpu']}; screenshots in {out})")


def test_no_traceback(outlines):
    assert_no_traceback(outlines[1])

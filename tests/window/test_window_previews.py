"""Loop, tubes, terrain, displacement-map and live parametric surface previews in a real Blender window (scenario
``previews``), on OpenGL and Vulkan: each drawn instead of its source and lit as Solid mode lights Blender's own
objects (studio lights and MatCap), so that it looks like its applied result drawn by Blender; hiding the source
hides the preview."""

import pytest
from test_window_tessellation import PREVIEW_BAR
from window_tier import assert_no_traceback, run_scenario, scenario_fixture, window_blender  # noqa: F401 -- fixtures

pytestmark = pytest.mark.window

PREVIEWS = ("loop", "tubes", "terrain", "displacement", "surface")
LIGHTINGS = ("", "_matcap")  # Solid mode's studio lighting, its MatCap lighting


previews = scenario_fixture("previews")


@pytest.mark.parametrize("lighting", LIGHTINGS)
@pytest.mark.parametrize("preview", PREVIEWS)
def test_preview_looks_like_the_applied_result(previews, preview, lighting):
    r, _, out = previews
    name = preview + lighting
    assert r[f"{name}_union_pixels"] > 10_000, f"the {name} should fill part of the view"
    assert r[f"{name}_vs_applied"] <= PREVIEW_BAR, (
        f"{r[f'{name}_vs_applied']:.1%} of the pixels of the {name} preview differ from Blender's drawing of the "
        f"applied result ({r['gpu']}; screenshots in {out})")


@pytest.mark.parametrize("name", ("loop", "tubes", "terrain"))
def test_hiding_the_source_hides_its_preview(previews, name):
    r, _, _ = previews
    assert r[f"{name}_source_hidden_pixels"] < 0.01 * r[f"{name}_union_pixels"]


def test_no_traceback(previews):
    assert_no_traceback(previews[1])

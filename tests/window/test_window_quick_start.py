"""The README's first quick start, run as printed in a real Blender window (scenario ``quick_start``): its steps are
the README's, in its order, and they give the picture the README shows beside them."""

import re

import pytest
from conftest import ROOT
from window_tier import (  # noqa: F401 -- fixtures
    assert_menu_labels,
    assert_no_traceback,
    assert_picture_current,
    assert_steps_in_order,
    run_scenario,
    scenario_constant,
    window_blender,
)

pytestmark = pytest.mark.window


def readme_step_one():
    text = (ROOT / "README.md").read_text()
    section = text[text.index("## Quick start in the viewport"):]
    return section[section.index("1. "):section.index("\n2. ")]


def test_the_readme_names_the_scenarios_steps_in_order():
    assert_steps_in_order(readme_step_one(), scenario_constant("quick_start", "STEPS"),
                          "the README's first quick-start step")


@pytest.fixture(scope="module")
def quick_start(run_scenario):  # noqa: F811
    return run_scenario("quick_start", "opengl")


def test_the_steps_give_a_smooth_result_over_a_hidden_source(quick_start):
    r, log, out = quick_start
    assert r["default_cube"], "the scenario should start from Blender's default scene"
    assert r["monkey_hidden"] and r["result_visible"], f"the monkey should be hidden under the new object ({out})"
    assert r["result_sharp_faces"] == 0 and r["result_faces"] > 10 * r["monkey_faces"]
    # the artist sees the change: smooth against faceted differs on a large share of the monkey
    assert r["changed_share"] > 0.2, f"only {r['changed_share']:.1%} of the monkey changed ({out})"
    assert abs(r["result_pixels"] - r["monkey_pixels"]) < 0.15 * r["monkey_pixels"]
    assert_no_traceback(log)


@pytest.mark.parametrize("name", ("quick_start", "quick_start_monkey"))
def test_the_readme_shows_what_the_steps_give(quick_start, name):
    _, _, out = quick_start
    assert f"docs/shots/{name}.png" in readme_step_one()
    assert_picture_current(out, name)


def test_each_menu_path_ends_in_the_label_of_the_operator_it_runs(quick_start):
    assert_menu_labels(quick_start[0])


def test_the_picture_command_lists_the_scenario():
    assert re.search(r"scenarios=\([^)]*\bquick_start\b", (ROOT / "tools" / "manual_shots.sh").read_text())

"""The manual's worked examples, run as each page prints them in a real Blender window (scenario
``worked_examples``): each page names the example's steps in order and shows the pictures the steps give now."""

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

EXAMPLES = scenario_constant("worked_examples", "EXAMPLES")


def worked_example(page):
    """The text of the page's *Worked example* section."""
    text = (ROOT / "docs" / page).read_text(encoding="utf-8")
    start = text.index("## Worked example")
    end = text.find("\n## ", start + 1)
    return text[start:end if end > 0 else None]


def pictures(example):
    """The pictures the scenario takes of ``example``: its result, and what Blender made before the tool (when a
    Blender step adds something before it)."""
    _, steps = EXAMPLES[example]
    first_tool = next(k for k, step in enumerate(steps) if step[1].startswith("tessera."))
    return [f"{example}_start", example] if first_tool >= 2 else [example]


@pytest.mark.parametrize("example", sorted(EXAMPLES))
def test_the_page_names_the_steps_in_order_and_shows_their_pictures(example):
    page, steps = EXAMPLES[example]
    section = worked_example(page)
    assert_steps_in_order(section, steps, f"{page}'s worked example")
    shown = re.findall(r"\]\(shots/([\w-]+)\.png\)", section)
    assert shown == pictures(example), f"{page} shows {shown}"


@pytest.fixture(scope="module")
def examples(run_scenario):  # noqa: F811
    return run_scenario("worked_examples", "opengl")


@pytest.mark.parametrize("example", sorted(EXAMPLES))
def test_the_steps_give_the_pages_pictures(examples, example):
    r, log, out = examples
    assert r[f"{example}_tab"] == "Tessera", "the sidebar should be open on the Tessera tab"
    assert r[f"{example}_faces"] > 0 and r[f"{example}_pixels"] > 2000, f"{example}: nothing made or shown ({out})"
    for name in pictures(example):
        assert_picture_current(out, name)
    assert_no_traceback(log)


def test_each_menu_path_ends_in_the_label_of_the_operator_it_runs(examples):
    assert_menu_labels(examples[0])


def test_the_picture_command_lists_the_scenario():
    assert re.search(r"scenarios=\([^)]*\bworked_examples\b", (ROOT / "tools" / "manual_shots.sh").read_text())

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
    """The pictures the scenario takes of ``example``: the view after its first steps (when it names a number of
    them), and its result."""
    _, _, start = EXAMPLES[example]
    return [f"{example}_start", example] if start else [example]


def test_every_capability_page_has_a_worked_example_run_in_the_window():
    """Each capability (a package of kernels/, its page in docs/) and the node groups' page: a worked example that the
    scenario runs."""
    capabilities = {p.name for p in (ROOT / "kernels").iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    pages = {f"{name}.md" for name in capabilities - {"common"}} | {"node_groups.md"}
    assert len(pages) >= 9 and pages <= {page for page, _, _ in EXAMPLES.values()}, pages


def steps_run(example):
    """What each step of ``example`` runs."""
    return [what for _, what, _ in EXAMPLES[example][1]]


@pytest.mark.parametrize("example", sorted(EXAMPLES))
def test_the_page_names_the_steps_in_order_and_shows_their_pictures(example):
    page, steps, _ = EXAMPLES[example]
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
    if f"{example}_image_spread" in r:  # an image, shown in the Image Editor: streaks, not one flat grey
        assert r[f"{example}_image_spread"] > 0.05, f"{example}: the image is flat ({out})"
    else:
        assert r[f"{example}_tab"] == "Tessera", "the sidebar should be open on the Tessera tab"
        made = r[f"{example}_faces"] if "check:tessera.nailboard.enabled" not in steps_run(example) else \
            r["boards_ready"]  # the object drawn from its board: its own faces are not drawn
        assert made > 0 and r[f"{example}_pixels"] > 2000, f"{example}: nothing made or shown ({out})"
    for name in pictures(example):
        assert_picture_current(out, name)
    assert_no_traceback(log)


def test_each_menu_path_ends_in_the_label_of_the_operator_it_runs(examples):
    assert_menu_labels(examples[0])


def test_each_tool_step_picks_the_toolbar_button_it_names(examples):
    """A step that picks a tool names the label of its toolbar button, and that tool is the active one after it."""
    named = {words: what.removeprefix("tool:") for _, steps, _ in EXAMPLES.values() for words, what, _ in steps
             if what.startswith("tool:")}
    assert named and examples[0]["tools"] == {words: [idname, words] for words, idname in named.items()}


def test_each_sidebar_step_names_the_label_it_clicks(examples):
    """A step that opens a panel or ticks a checkbox names the label the sidebar shows on it."""
    r = examples[0]
    for kind, recorded in (("panel:", r["panels"]), ("check:", r["checks"])):
        named = [words for _, steps, _ in EXAMPLES.values() for words, what, _ in steps if what.startswith(kind)]
        assert named and recorded == {words: words for words in named}, (kind, recorded)


def test_the_brush_stroke_paints_the_map(examples):
    assert examples[0]["displacement_map_texels_changed"] > 1000  # a ridge of radius 80 texels, not a few dabs


def test_the_triangle_counts_a_page_gives_are_what_its_steps_make(examples):
    """Each "about N triangles" of a worked example is within 2 % of the triangles its steps make in the window (the
    terrain's are the scene camera's: a renamed default or a changed level rule changes them)."""
    counted = set()
    for example, (page, _, _) in EXAMPLES.items():
        for figure in re.findall(r"about ([\d,]+) triangles", worked_example(page)):
            made = examples[0][f"{example}_triangles"]
            assert abs(int(figure.replace(",", "")) - made) <= 0.02 * made, f"{page}: about {figure}, made {made:,}"
            counted.add(example)
    assert "terrain" in counted


def test_the_picture_command_lists_the_scenario():
    assert re.search(r"scenarios=\([^)]*\bworked_examples\b", (ROOT / "tools" / "manual_shots.sh").read_text())

"""The add-on enabled in a real Blender window (scenario ``startup``), on OpenGL and Vulkan: its node-group library
is written by a worker Blender, so building the groups (one to two seconds of Python) never holds the window, and
the "Tessera" asset library appears, complete, when it is done. (The longest hold meanwhile is recorded for the
note, not asserted: timings are not tested.)"""

import pytest
from window_tier import assert_no_traceback, run_scenario, scenario_fixture, window_blender  # noqa: F401 -- fixtures

pytestmark = pytest.mark.window


startup = scenario_fixture("startup")


def test_the_node_library_is_written_by_a_worker_and_then_listed(startup):
    r, _, out = startup
    assert r["writer_seen"], f"the library should be written by a worker Blender ({out})"
    assert len(r["entries"]) == 1 and r["complete"], f"one complete Tessera asset library expected: {r['entries']}"


def test_no_traceback(startup):
    assert_no_traceback(startup[1])

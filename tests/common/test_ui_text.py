"""User-facing text in the source, checked without Blender: panel labels, reports, poll messages, error messages
(the guarded path turns them into reports), node-group socket descriptions and the tool's labels say what to do in
the artist's words; none cites a paper, an equation or a document outside the repository.

Only text a user can see is scanned (docstrings and comments may cite ``docs/references.md``): string constants given
to ``label``/``report``/``poll_message_set``, to the keywords ``text``, ``heading``, ``name`` and ``description`` of any
call, to ``raise`` of an error, and ``bl_label``/``bl_description`` class attributes. The RNA of the registered classes
is walked by ``test_blender_ui_text.py``.
"""

import ast
from pathlib import Path

from ui_rules import description_problems, jargon

ROOT = Path(__file__).resolve().parents[2]
PRODUCT = ("kernels", "gpu_shaders", "addon", "operators")
UI_CALLS = {"label", "report", "poll_message_set"}
UI_KEYWORDS = {"text", "heading", "name", "description"}


def _strings(node):
    """The literal text of a string constant or an f-string (its constant parts joined by "{}")."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.JoinedStr):
        return "{}".join(v.value for v in node.values if isinstance(v, ast.Constant) and isinstance(v.value, str))
    if isinstance(node, ast.BinOp):  # "a" + "b", "a %s" % x
        parts = [_strings(node.left), _strings(node.right)]
        return "".join(p for p in parts if p)
    return None


def ui_strings(path):
    """(line, text) of every user-facing string in the module at ``path``."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = []

    def add(node):
        text = _strings(node)
        if text:
            found.append((node.lineno, text))

    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            func = node.func
            name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
            if name in UI_CALLS:
                for arg in node.args:
                    add(arg)
            for kw in node.keywords:
                if kw.arg in UI_KEYWORDS:
                    add(kw.value)
        elif isinstance(node, ast.Raise) and isinstance(node.exc, ast.Call):
            for arg in node.exc.args:
                add(arg)
        elif isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id in ("bl_label", "bl_description")
                                                  for t in node.targets):
            add(node.value)
    return found


def product_files():
    return sorted(p for layer in PRODUCT for p in (ROOT / layer).rglob("*.py"))


def test_the_scan_sees_the_text_it_is_meant_to_see():
    """The scanner finds labels, reports, poll messages, raised messages and keyword texts (a scan that found
    nothing would pass everything)."""
    found = {text for path in product_files() for _, text in ui_strings(path)}
    assert len(found) > 300
    assert "Select a mesh" in found  # a poll message (displacement_add)
    assert any(t.startswith("Choose at least one metric") for t in found)  # a raised message
    assert "Custom Kernel" in found  # a panel label


def test_no_research_jargon_in_user_facing_text():
    bad = [f"{path.relative_to(ROOT)}:{line}: {found} in {text!r}"
           for path in product_files() for line, text in ui_strings(path) if (found := jargon(text))]
    assert not bad, "\n".join(bad)


def test_tool_and_panel_descriptions_are_one_sentence():
    bad = []
    for path in product_files():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "bl_description"
                                                    for t in node.targets):
                text = _strings(node.value)
                if problems := description_problems(text):
                    bad.append(f"{path.relative_to(ROOT)}:{node.lineno}: {problems}")
    assert not bad, "\n".join(bad)

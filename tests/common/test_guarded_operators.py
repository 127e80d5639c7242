"""Every operator runs through the one guarded path (`addon.guarded`): checked on the source, so a new operator
cannot skip it quietly."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _operator_classes(tree):
    for node in ast.walk(tree):
        if isinstance(node, ast.ClassDef) and any("Operator" in ast.unparse(b) for b in node.bases):
            yield node


def test_every_operator_execute_is_guarded():
    found, unguarded = 0, []
    for path in sorted((ROOT / "operators").glob("*.py")):
        for cls in _operator_classes(ast.parse(path.read_text(encoding="utf-8"))):
            for fn in cls.body:
                if isinstance(fn, ast.FunctionDef) and fn.name == "execute":
                    found += 1
                    decorators = [ast.unparse(d) for d in fn.decorator_list]
                    if "guarded" not in decorators or [a.arg for a in fn.args.args] != ["self", "context", "tx"]:
                        unguarded.append(f"{path.name}:{cls.name}")
    assert found >= 8, found
    assert unguarded == []

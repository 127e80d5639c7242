"""The architecture page stays a true map: every module of the product (what the zip ships) is named on it, by its
path or its file name, so a new module cannot arrive unexplained."""

import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
#: The product's folders (the top level DESIGN fixes, less tests, samples, bench, tools, docs).
PRODUCT = ("addon", "operators", "kernels", "gpu_shaders")


def _product_modules():
    listed = subprocess.run(["git", "ls-files", *PRODUCT], cwd=ROOT, capture_output=True, text=True, check=True)
    return [p for p in listed.stdout.split() if p.endswith(".py") and not p.endswith("__init__.py")]


def test_every_product_module_is_on_the_architecture_map():
    page = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    modules = _product_modules()
    assert len(modules) > 100
    missing = [m for m in modules if m not in page and f"`{Path(m).name}`" not in page]
    assert missing == [], f"docs/architecture.md does not name: {missing}"


def test_each_package_says_what_it_is_for_and_leaves_the_map_to_the_page():
    """A package's docstring says in a sentence or two what the folder is for; the list of its modules lives on the
    architecture page (checked above), not in docstrings that fall behind as modules arrive."""
    import ast

    listed = subprocess.run(["git", "ls-files", *PRODUCT], cwd=ROOT, capture_output=True, text=True, check=True)
    packages = [p for p in listed.stdout.split() if p.endswith("__init__.py")]
    assert len(packages) > 15
    for path in packages:
        tree = ast.parse((ROOT / path).read_text(encoding="utf-8"))
        doc = ast.get_docstring(tree)
        assert doc, f"{path} has no docstring"
        if path.count("/") == 1 or len(tree.body) > 3:  # top-level packages state rules; code documents itself
            continue
        modules = {Path(m).stem for m in _product_modules() if Path(m).parent == Path(path).parent}
        named = sorted(m for m in modules if f"`{m}`" in doc)
        assert len(doc.splitlines()) <= 4 and len(named) <= 2, f"{path}: {len(doc.splitlines())} lines, names {named}"


#: DESIGN's sizes: a module of about 500 lines at most (600 the limit), a function of at most 80.
MAX_MODULE_LINES, MAX_FUNCTION_LINES = 600, 80


def test_modules_and_functions_stay_small():
    """No product module over 600 lines and no product function over 80: a file that grows past them has taken on a
    second job, to be split by what it does (as the patch tessellator was)."""
    import ast

    long_modules, long_functions = [], []
    listed = subprocess.run(["git", "ls-files", *PRODUCT, "__init__.py"], cwd=ROOT, capture_output=True, text=True,
                            check=True)
    paths = [p for p in listed.stdout.split() if p.endswith(".py")]
    assert len(paths) > 150
    for path in paths:
        text = (ROOT / path).read_text(encoding="utf-8")
        if len(text.splitlines()) > MAX_MODULE_LINES:
            long_modules.append(f"{path}: {len(text.splitlines())} lines")
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                size = node.end_lineno - node.lineno + 1
                if size > MAX_FUNCTION_LINES:
                    long_functions.append(f"{path}: {node.name} {size} lines")
    assert not long_modules and not long_functions, long_modules + long_functions

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

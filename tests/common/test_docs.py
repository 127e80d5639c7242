"""The README is a front door and the manual is whole (no Blender needed): the README at most 12 KB; a page per
capability plus the general pages; every relative link and anchor of the README and docs/ resolves. The README's code
blocks are run by ``test_blender_readme.py``; the menu paths the docs name are resolved by ``test_blender_ui_text.py``.
"""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_the_readme_is_a_front_door():
    """At most 12 KB, and it links only to files that exist."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(text.encode()) <= 12 * 1024
    links = re.findall(r"\]\(([^)#\s]+)", text)
    assert len(links) >= 20
    missing = [link for link in links if not link.startswith("http") and not (ROOT / link).exists()]
    assert not missing, missing


def test_the_manual_has_a_page_per_capability_and_its_links_resolve():
    """docs/ holds a page per capability (the layers' capability packages) plus batch use, preferences, performance,
    architecture, development and references; every relative link of the README and the manual points at a file that
    exists, and every anchor at a heading or an anchor of that page."""
    capabilities = sorted(p.name for p in (ROOT / "kernels").iterdir() if p.is_dir() and p.name not in ("common",
                                                                                                       "__pycache__"))
    assert len(capabilities) >= 7
    pages = {p.stem for p in (ROOT / "docs").glob("*.md")}
    assert set(capabilities) | {"index", "batch", "preferences", "performance", "architecture", "development",
                                "references", "node_groups"} <= pages
    bad = []
    for page in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for target, anchor in re.findall(r"\]\(([^)#\s]*)(?:#([\w-]+))?\)", page.read_text(encoding="utf-8")):
            if target.startswith("http"):
                continue
            path = (page.parent / target).resolve() if target else page
            if not path.exists():
                bad.append(f"{page.name}: {target}")
            elif anchor and path.suffix == ".md":
                text = path.read_text(encoding="utf-8")
                headings = {re.sub(r"[^\w\- ]", "", h).strip().lower().replace(" ", "-")
                            for h in re.findall(r"(?m)^#+ (.*)$", text)}
                if anchor not in headings and f'id="{anchor}"' not in text:
                    bad.append(f"{page.name}: {target}#{anchor}")
    assert not bad, bad


def test_the_performance_summary_is_read_from_the_bench_tables_on_the_page():
    """The summary table at the top of docs/performance.md is what `tools/bench_report.py` reads back from the bench
    tables below it (never edited by hand), every row measured, each ratio the tables' own times."""
    import importlib.util

    root = Path(__file__).resolve().parents[2]
    spec = importlib.util.spec_from_file_location("bench_report", root / "tools" / "bench_report.py")
    report = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(report)
    page = (root / "docs" / "performance.md").read_text(encoding="utf-8")
    block = next(m for m in report.BLOCK.finditer(page) if m.group(2) == "summary").group(3)
    assert block.strip() == report.summary_block(page).strip()
    assert "not measured" not in block and block.count("\n| ") == len(report.SUMMARY) + 1
    row = next(r for r in report.page_rows(page, "tessellation") if r["case"] == "operator_pn_smooth")
    ratio = float(row["baseline seconds"]) / float(row["seconds"])
    assert f"| {ratio:.2f}x faster |" in block or f"| {1 / ratio:.2f}x slower |" in block


#: A speed figure in prose: "1.36x", "1.36–1.96x" (not a version such as "4.x").
_FIGURE = re.compile(r"(?<![\w.])(\d+(?:\.\d+)?)(?:[–-](\d+(?:\.\d+)?))?x\b")
#: Columns of the bench tables that hold a ratio between two measured times.
_RATIO_COLUMN = re.compile(r"speedup|ratio|faster|slower|/ ")


def _bench_ratios(page):
    """Every cell of a ratio column in the bench tables of ``page`` (docs/performance.md): its number, as printed."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("bench_report", ROOT / "tools" / "bench_report.py")
    report = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(report)
    found = set()
    for match in report.BLOCK.finditer(page):
        for row in report.page_rows(page, match.group(2)):
            for column, cell in row.items():
                number = re.match(r"\d+(?:\.\d+)?", cell or "")
                if _RATIO_COLUMN.search(column) and number:
                    found.add(number.group(0))
    return found


def test_every_speed_figure_in_prose_is_a_bench_ratio():
    """A figure such as "1.36–1.96x" in the README or a docs page (the performance page's own tables aside) is a ratio
    the bench wrote into docs/performance.md, each end of a range a measured row: prose cannot keep a number the
    bench no longer gives."""
    page = (ROOT / "docs" / "performance.md").read_text(encoding="utf-8")
    ratios = _bench_ratios(page)
    assert {"1.36", "1.96"} <= ratios  # the stencil rows the subdivision page cites
    stale = []
    for path in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        if path.name in ("performance.md", "changelog.md"):
            continue
        for line_no, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            for figure in _FIGURE.finditer(line):
                if not all(end in ratios for end in figure.groups() if end):
                    stale.append(f"{path.name}:{line_no}: {figure.group(0)}")
    assert not stale, f"speed figures that no bench table of docs/performance.md gives: {stale}"


def test_every_picture_of_the_window_is_shown():
    """Each picture tools/manual_shots.sh made (docs/shots/) is shown by the README or a docs page: none is left over
    from an example that was dropped."""
    shown = (ROOT / "README.md").read_text(encoding="utf-8") + "".join(
        p.read_text(encoding="utf-8") for p in (ROOT / "docs").glob("*.md"))
    pictures = sorted(p.name for p in (ROOT / "docs" / "shots").glob("*.png"))
    assert pictures
    assert [name for name in pictures if f"shots/{name})" not in shown] == []


def test_the_sample_files_are_what_their_tool_writes_and_each_is_linked():
    """docs/samples/ holds what tools/sample_height_map.py writes now, sample for sample, and a page links each file
    there (the manual ships the linked ones)."""
    import importlib.util

    import numpy as np
    import OpenImageIO as oiio

    spec = importlib.util.spec_from_file_location("sample_height_map", ROOT / "tools" / "sample_height_map.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    buf = oiio.ImageBuf(str(tool.SAMPLE))
    assert buf.spec().format == oiio.UINT16 and buf.spec().nchannels == 1
    assert np.array_equal(buf.get_pixels(oiio.UINT16)[..., 0], tool.height_map())
    pages = "".join(p.read_text(encoding="utf-8") for p in (ROOT / "docs").glob("*.md"))
    files = sorted(p.name for p in (ROOT / "docs" / "samples").iterdir())
    assert files == [tool.SAMPLE.name] and all(f"](samples/{name})" in pages for name in files)


def test_the_changelog_starts_at_the_manifests_version():
    """docs/changelog.md's newest heading is the version the manifest gives the extension, so a release cannot ship
    without saying what changed."""
    import tomllib

    version = tomllib.loads((ROOT / "blender_manifest.toml").read_text(encoding="utf-8"))["version"]
    headings = re.findall(r"(?m)^## (\d+\.\d+\.\d+)\b", (ROOT / "docs" / "changelog.md").read_text(encoding="utf-8"))
    assert headings and headings[0] == version, (headings, version)

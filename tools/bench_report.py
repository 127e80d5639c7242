"""Run the benchmarks and write their tables into docs/performance.md: no figure in those tables is copied by hand.

Each ``bench/*.py`` prints one JSON object per line (a case: its figures, the baseline measured in the same run, their
ratio). This script runs them one after another (``--run``) and keeps each one's lines in ``out/bench/<name>.jsonl``,
then rewrites every block of docs/performance.md that sits between ``<!-- bench:NAME -->`` and
``<!-- /bench:NAME -->`` with the tables of ``out/bench/NAME.jsonl`` (rows with the same fields share a table), and
the run's date, machine and Blender in the block ``<!-- bench:machine -->``. Text outside the blocks is left alone.

Usage:
    python tools/bench_report.py --run            # run every bench, then write the page (what `make bench` does)
    python tools/bench_report.py --run tubes      # run some, then write the page from whatever out/bench holds
                                                  # (a bench not run here keeps its block as it is)
    python tools/bench_report.py                  # write the page from out/bench as it is
"""

import argparse
import datetime
import json
import os
import platform
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "out" / "bench"
PAGE = ROOT / "docs" / "performance.md"
BLOCK = re.compile(r"(<!-- bench:([\w-]+) -->\n)(.*?)(<!-- /bench:\2 -->)", re.DOTALL)


def benches():
    return sorted(p.stem for p in (ROOT / "bench").glob("*.py") if not p.stem.startswith("_"))


def run(names):
    """Run each bench in its own process; keep its JSON lines (and a record of a failure) in out/bench. Returns the
    names of the benches that failed."""
    OUT.mkdir(parents=True, exist_ok=True)
    failed = []
    for name in names:
        print(f"bench_report: running bench/{name}.py", flush=True)
        proc = subprocess.run([sys.executable, str(ROOT / "bench" / f"{name}.py")], cwd=ROOT, capture_output=True,
                              text=True)
        rows = []
        for line in proc.stdout.splitlines():
            line = line.strip()
            if line.startswith("{"):
                try:
                    rows.append(json.loads(line))
                except json.JSONDecodeError:
                    continue
        if proc.returncode != 0:
            rows.append({"case": "failed", "exit_code": proc.returncode, "stderr": proc.stderr.strip()[-300:]})
        (OUT / f"{name}.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows), encoding="utf-8")
        sys.stdout.write(proc.stdout)
        if proc.returncode != 0:
            sys.stderr.write(proc.stderr[-3000:])
            failed.append(name)
    (OUT / "machine.json").write_text(json.dumps(machine()), encoding="utf-8")
    return failed


def machine():
    """Where and when the benches ran: date, CPU, cores, memory, Blender, OpenCL device."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    info = {"date": datetime.date.today().isoformat(), "cpu": cpu, "cores": os.cpu_count(),
            "python": platform.python_version()}
    try:
        pages = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        info["memory_gib"] = round(pages / 2**30)
    except (ValueError, OSError, AttributeError):
        pass
    probe = ("import bpy, json; from pathlib import Path; import sys; sys.path.insert(0, 'bench'); "
             "from _setup import import_path; import_path(); "
             "from tessera.kernels.common.opencl_runtime import get_runtime; r = get_runtime(); "
             "print(json.dumps({'blender': bpy.app.version_string, 'opencl': r.description if r else 'none'}))")
    proc = subprocess.run([sys.executable, "-c", probe], cwd=ROOT, capture_output=True, text=True)
    lines = [line for line in proc.stdout.splitlines() if line.startswith("{")]
    if lines:
        info.update(json.loads(lines[-1]))
    return info


def _cell(value):
    if value is None:
        return "–"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        if value != value:
            return "nan"
        magnitude = abs(value)
        if magnitude >= 1000:
            return f"{value:,.0f}"
        if magnitude >= 10:
            return f"{value:.1f}"
        if magnitude >= 0.01 or value == 0:
            return f"{value:.3g}"
        return f"{value:.2e}"
    if isinstance(value, int):
        return f"{value:,}"
    if isinstance(value, (list, dict)):
        return "`" + json.dumps(value).replace("|", "\\|") + "`"
    return str(value).replace("|", "\\|").replace("\n", " ")


def tables(rows):
    """Markdown tables of ``rows`` (dicts): one table per set of fields, in the order the fields first appear."""
    groups = {}
    for row in rows:
        row = {k: v for k, v in row.items() if k != "bench"}
        groups.setdefault(tuple(row), []).append(row)
    out = []
    for fields, group in groups.items():
        out.append("| " + " | ".join(f.replace("_", " ") for f in fields) + " |")
        out.append("|" + "---|" * len(fields))
        out += ["| " + " | ".join(_cell(r[f]) for f in fields) + " |" for r in group]
        out.append("")
    return "\n".join(out)


def machine_block():
    path = OUT / "machine.json"
    if not path.exists():
        return "*(no bench run yet: `make bench`)*\n"
    m = json.loads(path.read_text(encoding="utf-8"))
    parts = [f"{m.get('date', '?')}", f"{m.get('cpu', '?')}, {m.get('cores', '?')} cores"]
    if "memory_gib" in m:
        parts.append(f"{m['memory_gib']} GiB")
    parts += [f"Blender {m.get('blender', '?')}", f"OpenCL: {m.get('opencl', '?')}"]
    return "*Measured " + "; ".join(parts) + ".*\n"


#: The summary's rows, each one bench row read back from the page: (Tessera's tool and input, bench, case, Tessera's
#: time column, the baseline's time column, Tessera's output size column, the baseline's (None: the same output)).
SUMMARY = (
    ("Tessellate, PN, smooth Suzanne", "tessellation", "operator_pn_smooth", "seconds", "baseline seconds",
     "output triangles", "baseline triangles"),
    ("Tessellate, Phong, smooth Suzanne", "tessellation", "operator_phong_smooth", "seconds", "baseline seconds",
     "output triangles", "baseline triangles"),
    ("Tubes from 100,000 hair strands", "tubes", "operator", "median seconds", "baseline median seconds", None, None),
    ("Loop Subdivide, level 5, flat Suzanne", "subdivision", "operator_level_5", "seconds", "baseline seconds",
     "output triangles", "baseline triangles"),
    ("Tessellate Surface, the teapot, same deviation", "surfaces", "tessellate_surface_teapot", "seconds",
     "baseline seconds", "triangles", "baseline triangles"),
    ("Tessera PN node group, level 4", "node_groups", "pn_group_level_4_vs_subsurf", "seconds", "baseline seconds",
     "output triangles", "baseline triangles"),
    ("Tessera Tubes node group, 3,000 curves", "node_groups", "tubes_group_3000x40_vs_curve_to_mesh", "seconds",
     "baseline seconds", "output quads", "baseline quads"),
    ("Tessera Terrain node group, 1025² map", "node_groups", "terrain_group_1025_vs_displace", "seconds",
     "baseline seconds", "output triangles", "baseline triangles"),
    ("Live tessellation preview, a redraw", "window", "redraw, tessellation (PN, level 3) preview", "preview ms",
     "blender ms", None, None),
    ("Live Loop preview, a redraw", "window", "redraw, Loop (2 levels) preview", "preview ms", "blender ms", None,
     None),
    ("Live tubes preview, a redraw", "window", "redraw, tubes (16 sides) preview", "preview ms", "blender ms", None,
     None),
    ("Live terrain preview, a redraw", "window", "redraw, terrain (257² heights) preview", "preview ms", "blender ms",
     None, None),
)


def page_rows(text, bench):
    """The rows of bench ``bench``'s tables on the page ``text``: dicts of column -> cell text, in page order."""
    match = next((m for m in BLOCK.finditer(text) if m.group(2) == bench), None)
    rows = []
    if match is None:
        return rows
    for table in match.group(3).strip().split("\n\n"):
        lines = [line for line in table.splitlines() if line.startswith("|")]
        if len(lines) < 3:
            continue
        head = [c.strip() for c in lines[0].strip().strip("|").split("|")]
        for line in lines[2:]:
            cells = [c.strip() for c in re.split(r"(?<!\\)\|", line.strip().strip("|"))]
            rows.append(dict(zip(head, cells, strict=False)))
    return rows


def _number(cell):
    return float(cell.replace(",", ""))


def summary_block(text):
    """The summary table of the page ``text``: for each `SUMMARY` row, the Blender tool it was measured against, how
    much faster or slower Tessera was in wall time, and how its output compares, read from the bench tables on the
    same page (their rounded figures: a ratio here may differ from the table's own in its last digit)."""
    out = ["| Tessera | against, in Blender | wall time | output |", "|---|---|---|---|"]
    for label, bench, case, ours, theirs, size, their_size in SUMMARY:
        row = next((r for r in page_rows(text, bench) if r.get("case") == case), None)
        if row is None or ours not in row or theirs not in row:
            out.append(f"| {label} | – | not measured (`bench/{bench}.py`) | – |")
            continue
        faster = _number(row[theirs]) / _number(row[ours])
        against = row.get("baseline") or ("Blender drawing the applied mesh" if bench == "window" else "–")
        if row.get("backend"):
            label = f"{label} ({row['backend']})"
        verdict = f"{faster:.2f}x faster" if faster >= 1.0 else f"{1.0 / faster:.2f}x slower"
        share = _number(row[size]) / _number(row[their_size]) if size else 1.0
        output = "the same" if abs(share - 1.0) <= 0.05 else f"{share:.2f}x the {size.split()[-1]}"
        out.append(f"| {label} | {against} | {verdict} | {output} |")
    return "\n".join(out) + "\n"


def write_page(machine_too=True):
    """Fill the page's blocks from out/bench; the machine block only with ``machine_too`` (a run of every bench:
    after a partial run the page's other tables still come from the machine it names)."""
    text = PAGE.read_text(encoding="utf-8")

    def fill(match):
        name = match.group(2)
        if name == "summary":
            return match.group(0)  # written below, from the other blocks' new tables
        if name == "machine":
            if not machine_too:
                return match.group(0)
            body = machine_block()
        else:
            path = OUT / f"{name}.jsonl"
            if not path.exists() and match.group(3).strip():
                return match.group(0)  # not run here: the block keeps the tables of the run that wrote it
            rows = [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines() if line.strip()] \
                if path.exists() else []
            body = tables(rows) if rows else f"*(bench/{name}.py has not been run: `make bench`)*\n"
        return f"{match.group(1)}\n{body.rstrip()}\n\n{match.group(4)}"

    new = BLOCK.sub(fill, text)
    new = BLOCK.sub(lambda m: f"{m.group(1)}\n{summary_block(new).rstrip()}\n\n{m.group(4)}" if m.group(2) == "summary"
                    else m.group(0), new)
    missing = sorted(set(benches()) - {m.group(2) for m in BLOCK.finditer(text)})
    if missing:
        raise SystemExit(f"bench_report: docs/performance.md has no block for {missing}")
    PAGE.write_text(new, encoding="utf-8")
    print(f"bench_report: wrote {PAGE.relative_to(ROOT)}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", nargs="*", metavar="BENCH", help="run these benches (none named: all) first")
    args = parser.parse_args()
    if args.run is not None:
        unknown = set(args.run) - set(benches())
        if unknown:
            raise SystemExit(f"bench_report: no bench called {sorted(unknown)}")
        failed = run(args.run or benches())
    # the machine line names where the page's tables were measured: only when out/bench holds every bench's rows
    write_page(machine_too=all((OUT / f"{name}.jsonl").exists() for name in benches()))
    if args.run is not None and failed:
        raise SystemExit(f"bench_report: these benches failed (their rows say how): {failed}")


if __name__ == "__main__":
    main()

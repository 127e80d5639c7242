"""``blender -c tessera plan VERB ...``: a large job as independent tasks for a render farm, printed as JSON.

Each task is a complete command line (``blender -c tessera VERB ...``) that runs alone on any machine that sees the
same files (paths are made absolute); Tessera schedules nothing itself. Splits:

- per-object verbs: one task per source object, each writing its own output (``{object}`` in the name; added before
  the extension when the name has none);
- ``terrain``: ``--blocks CxR`` tasks per frame, one block each, and per frame a ``join`` task (to run after them)
  that welds the blocks into exactly the mesh one process makes: levels are chosen for the whole terrain in every
  task, so the blocks' shared edges have one level and one set of points.
"""

import glob
import json
import os

from . import files

#: The ``{block}`` part of a block's output name.
BLOCK = "{block}"


def _render_value(p, value):
    if p.type == "BOOLEAN" and not getattr(p, "array_length", 0):
        return None
    if isinstance(value, (set, frozenset)):
        return ",".join(sorted(v.lower() for v in value))
    if isinstance(value, tuple):
        return ",".join(repr(v) if isinstance(v, float) else str(v) for v in value)
    if p.type == "ENUM":
        return value.lower()
    return repr(value) if isinstance(value, float) else str(value)


def task_argv(verb, args, props, inputs=None, objects=None, out=None, frame=None, block=None):
    """The command-line words of one task of ``verb``: its parsed ``args`` with the given parts replaced."""
    argv = [verb.name] + [os.path.abspath(p) for p in (args.inputs if inputs is None else inputs)]
    objects = objects if objects is not None else getattr(args, "objects", None)
    if objects:
        argv += ["--objects", objects]
    argv += ["-o", os.path.abspath(out or args.out)]
    if args.camera:
        argv += ["--camera", args.camera]
    frame = args.frame if frame is None else frame
    if frame is not None:
        argv += ["--frame", str(frame)]
    for p in props:
        value = block if (p.identifier == "block" and block is not None) else getattr(args, p.identifier)
        if value is None:
            continue
        word = _render_value(p, value)
        flag = "--" + p.identifier.replace("_", "-")
        if word is None:
            argv.append(flag if value else "--no-" + flag[2:])
        else:
            argv += [flag, word]
    return argv


def _with_part(pattern, part):
    """``pattern`` with ``part`` (e.g. ``{object}``) in its name: where the name says, else before the extension."""
    if part in pattern:
        return pattern
    stem, ext = os.path.splitext(pattern)
    return f"{stem}_{part}{ext}"


def _task(name, argv, outputs, after=()):
    return {"name": name, "argv": argv, "command": ["blender", "-c", "tessera"] + argv, "outputs": outputs,
            "after": list(after)}


def plan_objects(verb, args, props, targets):
    """One task per object in ``targets``."""
    pattern = _with_part(args.out, "{object}")
    tasks = []
    for ob in targets:
        out = files.output_name(pattern, ob.name)
        argv = task_argv(verb, args, props, objects=glob.escape(ob.name).replace(",", "[,]"), out=pattern)
        tasks.append(_task(f"{verb.name} {ob.name}", argv, [os.path.abspath(out)]))
    return tasks


def plan_terrain(verb, args, props, frames, blocks):
    """``blocks`` = (columns, rows) tasks per frame in ``frames`` (None: the one frame), and a join per frame."""
    cols, rows = blocks
    pattern = _with_part(args.out, BLOCK)
    tasks = []
    for frame in frames or [args.frame]:
        names = []
        for row in range(rows):
            for col in range(cols):
                out = files.output_name(pattern.replace(BLOCK, f"b{col}-{row}"), None, frame)
                argv = task_argv(verb, args, props, out=out, frame=frame, block=(col, row, cols, rows))
                name = f"terrain block {col},{row}" + ("" if frame is None else f" frame {frame}")
                tasks.append(_task(name, argv, [os.path.abspath(out)]))
                names.append(name)
        joined = files.output_name(args.out, None, frame)
        parts = [t["outputs"][0] for t in tasks[-len(names):]]
        tasks.append(_task("join" + ("" if frame is None else f" frame {frame}"),
                           ["join"] + parts + ["-o", os.path.abspath(joined)], [os.path.abspath(joined)], names))
    return tasks


def blocks_arg(text):
    """``CxR`` -> (columns, rows)."""
    c, _, r = text.lower().partition("x")
    cols, rows = int(c), int(r or c)
    if cols < 1 or rows < 1 or cols * rows > 4096:
        raise ValueError(text)
    return cols, rows


def print_plan(verb, tasks, to=None):
    """Print the plan as JSON, or write it to the file ``to`` (Blender may print lines of its own)."""
    text = json.dumps({"verb": verb.name, "tasks": tasks}, indent=1)
    if to in (None, "-"):
        print(text, flush=True)
        return
    with open(to, "w", encoding="utf-8") as f:
        f.write(text + "\n")


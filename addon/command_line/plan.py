"""``blender -c tessera plan VERB ...``: a large job as independent tasks for a render farm, printed as JSON (or as a
scheduler's own job: `schedulers`).

Each task is a complete command line (``blender -c tessera VERB ...``) that runs alone on any machine that sees the
same files (paths are made absolute); Tessera schedules nothing itself. Tasks come in steps: a step's tasks differ
only in their parameters (``{{Task.Param.NAME}}`` in the step's ``argv``, Open Job Description's notation), and a step
runs after the steps it names. Splits:

- per-object verbs: one task per source object, each writing its own output (``{object}`` in the name; added before
  the extension when the name has none);
- ``terrain``: ``--blocks CxR`` tasks per frame, one block each, and per frame a ``join`` task (to run after them)
  that welds the blocks into exactly the mesh one process makes: each block's levels are those the whole terrain
  gives, so the blocks' shared edges have one level and one set of points. A task reads only its block and the ring
  of tiles around it; the no-data voids of elevation files (filled over whole regions) are found and filled once,
  when the plan is made, into a void index beside the outputs (`void_index_name`) that every block task reads.
"""

import glob
import os
import re

from . import files

#: The ``{block}`` part of a block's output name.
BLOCK = "{block}"


def param(name):
    """The placeholder of task parameter ``name`` in a step's argv."""
    return "{{Task.Param." + name + "}}"


def fill(argv, params):
    """A step's ``argv`` with its placeholders replaced by one task's ``params`` (name -> value)."""
    out = []
    for word in argv:
        for name, value in params.items():
            word = word.replace(param(name), str(value))
        out.append(word)
    return out


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


def task_argv(verb, args, props, inputs=None, objects=None, out=None, frame=None, settings=None):
    """The command-line words of one task of ``verb``: its parsed ``args`` with the given parts replaced (``settings``:
    operator settings by identifier, e.g. a terrain's ``block``)."""
    settings = settings or {}
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
        value = settings.get(p.identifier, getattr(args, p.identifier))
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


def _task(name, argv, outputs, after=(), step="", params=None):
    return {"name": name, "argv": argv, "command": ["blender", "-c", "tessera"] + argv, "outputs": outputs,
            "after": list(after), "step": step, "params": dict(params or {})}


def _step(name, argv, params, after=()):
    return {"name": name, "argv": argv, "params": list(params), "after": list(after)}


def plan_objects(verb, args, props, targets):
    """One task per object in ``targets``: ``(steps, tasks)``."""
    pattern = _with_part(args.out, "{object}")
    template = task_argv(verb, args, props, objects=param("Object"), out=pattern)
    tasks = []
    for ob in targets:
        out = files.output_name(pattern, ob.name)
        values = {"Object": glob.escape(ob.name).replace(",", "[,]")}
        tasks.append(_task(f"{verb.name} {ob.name}", fill(template, values), [os.path.abspath(out)],
                           step="Objects", params=values))
    return [_step("Objects", template, ["Object"])], tasks


def plan_terrain(verb, args, props, frames, blocks, void_index=None):
    """``blocks`` = (columns, rows) tasks per frame in ``frames`` (None: the one frame), and a join per frame:
    ``(steps, tasks)``. Output names keep their frame pattern (``####``) and each task is given ``--frame``, so a
    step's tasks differ only in their frame and block. ``void_index``: the void index every block task reads (made
    by `void_index_name`'s caller before the plan is printed), None for data without one."""
    cols, rows = blocks
    pattern = _with_part(args.out, BLOCK)
    framed = frames is not None
    settings = {"block": param("Block")}
    if void_index:
        settings["void_index"] = os.path.abspath(void_index)
    block_argv = task_argv(verb, args, props, out=pattern.replace(BLOCK, param("Part")),
                           frame=param("Frame") if framed else None, settings=settings)
    parts = [os.path.abspath(pattern.replace(BLOCK, f"b{col}-{row}")) for row in range(rows) for col in range(cols)]
    join_argv = ["join"] + parts + ["-o", os.path.abspath(args.out)] + (["--frame", param("Frame")] if framed else [])
    names = ["Frame"] if framed else []
    steps = [_step("Blocks", block_argv, names + ["Block", "Part"]), _step("Join", join_argv, names, ["Blocks"])]
    tasks = []
    for frame in frames or [args.frame]:
        at = {"Frame": frame} if framed else {}
        suffix = "" if frame is None else f" frame {frame}"
        block_names = []
        for row in range(rows):
            for col in range(cols):
                values = dict(at, Block=f"{col},{row},{cols},{rows}", Part=f"b{col}-{row}")
                out = files.output_name(pattern.replace(BLOCK, values["Part"]), None, frame)
                name = f"terrain block {col},{row}{suffix}"
                tasks.append(_task(name, fill(block_argv, values), [os.path.abspath(out)], step="Blocks",
                                   params=values))
                block_names.append(name)
        joined = files.output_name(args.out, None, frame)
        tasks.append(_task("join" + suffix, fill(join_argv, at), [os.path.abspath(joined)], block_names,
                           step="Join", params=at))
    return steps, tasks


def void_index_name(out):
    """Where a terrain plan writes its void index: beside the outputs ``out`` (a pattern), named after them without
    their frame and block parts (``terrain_####.blend`` -> ``terrain.tessera-voids``)."""
    folder, base = os.path.split(os.path.abspath(out))
    stem = os.path.splitext(base)[0]
    for part in ("{frame}", BLOCK, "{object}"):
        stem = stem.replace(part, "")
    stem = re.sub(r"#+", "", stem).strip("_-. ") or "terrain"
    return os.path.join(folder, stem + ".tessera-voids")


def blocks_arg(text):
    """``CxR`` -> (columns, rows)."""
    c, _, r = text.lower().partition("x")
    cols, rows = int(c), int(r or c)
    if cols < 1 or rows < 1 or cols * rows > 4096:
        raise ValueError(text)
    return cols, rows


def plan_dict(verb, steps, tasks):
    """The plan as JSON data: the verb, its steps and its tasks."""
    return {"verb": verb.name, "steps": steps, "tasks": tasks}


def print_plan(text, to=None):
    """Print the plan's ``text``, or write it to the file ``to`` (Blender may print lines of its own)."""
    if to in (None, "-"):
        print(text, flush=True)
        return
    with open(to, "w", encoding="utf-8") as f:
        f.write(text + "\n")


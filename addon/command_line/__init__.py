"""Tessera on the command line: ``blender -c tessera VERB ...`` (Blender 4.2+ runs an extension's registered command
with the remaining arguments, in background mode, after the user's add-ons are enabled).

Verbs: tessellate, tubes, loop, surface, impostors, terrain (`verbs`), join (`join`), and plan (`plan`: a large job
as independent farm tasks). ``--help`` after any verb lists its options, made from its operator's settings. Exit
codes: 0 success, 1 failure (nothing written), 2 bad arguments. The same entry point, `execute`, runs from the ``bpy``
module: ``execute(["tessellate", "scene.blend", "--level", "4", "-o", "out.glb"])``.
"""

import os
import signal
import sys
import time

import bpy

from ...kernels.common.errors import TesseraError
from . import files, join, plan, schedulers, stopping, verbs

COMMAND = "tessera"
_handles = []

_USAGE = f"""usage: blender -c {COMMAND} VERB [FILES] [OPTIONS] -o OUTPUT

Verbs:
""" + "".join(f"  {v.name:<11} {v.summary}\n" for v in verbs.VERBS.values()) + """\
  join        Join the meshes of several files into one object, welding vertices that coincide exactly
  plan        Print a large job as independent tasks for a render farm (JSON): plan VERB ... [--blocks CxR]

'blender -c tessera VERB --help' lists a verb's options. Exit codes: 0 done, 1 failed (nothing written),
2 bad arguments.
"""


def join_parser():
    """The parser of ``join``."""
    p = verbs._Parser(prog=f"blender -c {COMMAND} join", allow_abbrev=False,
                      description="Join the meshes of several files (.blend or any importable mesh file) into one "
                                  "object, welding the vertices that coincide exactly: the blocks a farm meshed of "
                                  "one terrain become the terrain one process makes.")
    p.add_argument("inputs", nargs="+", metavar="FILE", help="the files to join")
    p.add_argument("-o", "--out", metavar="FILE", required=True,
                   help="where to write the joined object: .blend or " + ", ".join(sorted(files.EXPORTERS)))
    p.add_argument("--name", default=None, help="the joined object's name (default: the output's name)")
    p.add_argument("--json", nargs="?", const="-", metavar="FILE", help="print a JSON summary as the last line")
    p.add_argument("--frame", type=int, default=None, metavar="N",
                   help="put N for the frame pattern (#### or {frame}) in the files' names: one frame's join of a "
                        "plan whose tasks differ only in their frame")
    return p


def _join(argv):
    args = join_parser().parse_args(argv)
    if args.frame is not None:
        args.inputs = [files.output_name(p, None, args.frame) for p in args.inputs]
        args.out = files.output_name(args.out, None, args.frame)
    files.check_output(args.out)
    for path in args.inputs:
        files.check_input(path, {".blend", *files.IMPORTERS})
    verbs.probe_outputs(args)
    summary, outputs, t0 = verbs.Summary("join"), files.Outputs(), time.perf_counter()
    try:
        objects = join.read_meshes(args.inputs)
        if not objects:
            raise verbs.Usage("The files hold no mesh object to join")
        name = args.name or os.path.splitext(os.path.basename(args.out))[0]
        ob = join.join(objects, name)
        for other in objects:
            bpy.data.objects.remove(other)
        v, f = len(ob.data.vertices), len(ob.data.polygons)
        summary.results.append({"source": ", ".join(args.inputs), "objects": [ob.name], "vertices": v, "faces": f})
        verbs._say(f"joined {len(objects)} meshes: {v:,} vertices, {f:,} faces")
        outputs.write(args.out, [ob])
        verbs.finish(args, summary, outputs, t0)
    finally:
        outputs.discard()
        if not summary.ok:
            verbs._summary_out(args, summary)
    return verbs.EXIT_OK


def plan_parser():
    """The parser of ``plan`` (its own options; the verb's follow it)."""
    p = verbs._Parser(prog=f"blender -c {COMMAND} plan", allow_abbrev=False, add_help=False,
                      description="Print the independent tasks of a job (or write them to the file given with --json "
                                  "FILE), each a command line for any machine: one per object (per-object verbs) "
                                  "or one per block of --blocks CxR per frame (terrain, with a join task per "
                                  "frame), as JSON or as a scheduler's job (--format). Tessera runs none of them.")
    p.add_argument("verb", choices=sorted(verbs.VERBS))
    p.add_argument("--blocks", type=plan.blocks_arg, default=(2, 2), metavar="CxR",
                   help="terrain: split into C columns by R rows of tiles (default 2x2)")
    p.add_argument("--format", choices=schedulers.FORMATS, default="json",
                   help="json: the plan (default); openjd: an Open Job Description job template (Deadline Cloud, "
                        "'openjd run'); slurm: a script that submits one sbatch array job per step; flamenco: a "
                        "Flamenco 3 job type holding the plan")
    return p


def _plan(argv):
    p = plan_parser()
    if argv in ([], ["--help"], ["-h"]):
        p.print_help()
        return verbs.EXIT_OK
    mine, rest = p.parse_known_args(argv)
    verb = verbs.VERBS[mine.verb]
    parser = verbs.parser_for(verb)
    args = parser.parse_args(rest)
    props = verbs.operator_settings(verb)
    verbs._check_outputs(verb, args, 1)
    if verb.name == "terrain":
        frames = verbs.terrain_frames(args)
        if args.g == "LOG" or args.t_min_rule in ("LOG2", "PRINTED"):
            print("tessera: warning: the Log roughness curve and the Log2/As Printed error rules use log2, whose last "
                  "bit can differ between processors: on a farm of mixed machines, blocks may not weld exactly "
                  "(keep --g sqrt --t-min-rule search)", file=sys.stderr, flush=True)
        steps, tasks = plan.plan_terrain(verb, args, props, frames, mine.blocks, _void_index(args))
    else:
        files.read_inputs(args.inputs)
        steps, tasks = plan.plan_objects(verb, args, props, verbs.targets(verb, args.objects))
    plan.print_plan(schedulers.render(mine.format, plan.plan_dict(verb, steps, tasks)), args.json)
    return verbs.EXIT_OK


def _void_index(args):
    """Find the no-data voids of the terrain's elevation files once, for every block task, and write them beside the
    outputs (`plan.void_index_name`): the index's path, or None for a height map without one (an image, a raw file).
    Reads the whole data once, so that no task has to."""
    from ..terrain import data as terrain_data

    _, maps = verbs.terrain_inputs(args)
    settings = verbs.terrain_source(args, maps)
    if terrain_data.elevation_files(settings) is None:
        return None
    path = plan.void_index_name(args.out)
    verbs._say(f"plan: finding the no-data voids of {os.path.basename(maps[0])} once for every block task")
    count = []
    files.write_with(path, lambda target: count.append(terrain_data.write_void_index(settings, target))).commit()
    verbs._say(f"plan: {count[0]:,} void samples; the void index is {path}")
    return path


def execute(argv):
    """Run ``blender -c tessera`` with the words after it; returns the exit code (0, 1 or 2)."""
    argv = list(argv)
    if not argv or argv[0] in ("-h", "--help", "help"):
        print(_USAGE, end="", flush=True)
        return verbs.EXIT_OK if argv else verbs.EXIT_USAGE
    verb, rest = argv[0], argv[1:]
    stopping.requested.clear()
    previous = signal.signal(signal.SIGTERM, stopping.handler) if _main_thread() else None
    try:
        if verb == "plan":
            return _plan(rest)
        if verb == "join":
            return _join(rest)
        if verb not in verbs.VERBS:
            raise verbs.Usage(f"blender -c {COMMAND}: no verb {verb!r}; the verbs are "
                              f"{', '.join(list(verbs.VERBS) + ['join', 'plan'])}")
        return verbs.run(verb, rest)
    except SystemExit as done:  # --help
        return int(done.code or 0)
    except verbs.Usage as err:
        print(f"{err}\n(blender -c {COMMAND} {verb} --help lists the options)", file=sys.stderr, flush=True)
        return verbs.EXIT_USAGE
    except files.FileProblem as err:  # an input that cannot be used
        print(f"tessera: {err}", file=sys.stderr, flush=True)
        return verbs.EXIT_USAGE
    except (files.WriteFailed, stopping.Stopped, KeyboardInterrupt, TesseraError) as err:
        print(f"tessera: {err}", file=sys.stderr, flush=True)
        return verbs.EXIT_FAILED
    except RuntimeError as err:  # an importer or exporter refused
        print(f"tessera: {err}", file=sys.stderr, flush=True)
        return verbs.EXIT_FAILED
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _main_thread():
    import threading

    return threading.current_thread() is threading.main_thread()


def register():
    register_command = getattr(bpy.utils, "register_cli_command", None)
    if register_command is not None:
        _handles.append(register_command(COMMAND, execute))


def unregister():
    while _handles:
        bpy.utils.unregister_cli_command(_handles.pop())


__all__ = ["execute"]

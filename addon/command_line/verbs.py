"""The verbs of ``blender -c tessera VERB ...``: each runs one Tessera operator through its guarded path, on the objects
or files named, and writes the results through Blender's exporters (`files`).

Per-object verbs (tessellate, tubes, loop, surface, impostors) run their operator once per source object, each alone
selected and active, so the same object gives the same result whether it is baked with others or in a task of its
own. ``terrain`` meshes height maps (one block of a split with ``--block``, for each frame of ``--frames``). ``join``
puts the meshes of several outputs together and welds the vertices that coincide exactly (the blocks of a terrain).

A run either writes every output or none: when one object fails the others are still tried (every failure is
reported), then nothing is written and the exit code is 1.
"""

import argparse
import fnmatch
import json
import os
import re
import sys
import time
from dataclasses import asdict, dataclass, field
from types import SimpleNamespace

import bpy

from ...kernels.common.errors import InvalidInputError
from ...kernels.terrain.lod import block_tiles
from . import files, stopping
from .options import add_options, chosen, operator_rna, settable

EXIT_OK, EXIT_FAILED, EXIT_USAGE = 0, 1, 2


@dataclass(frozen=True)
class Verb:
    """A command-line verb: the operator it runs, the object types it takes (``kinds``; those taken when no
    ``--objects`` is given: ``default_kinds``), operator options the command line sets itself (``fixed``)."""

    name: str
    operator: str
    summary: str
    kinds: frozenset = frozenset()
    default_kinds: frozenset = frozenset()
    fixed: dict = field(default_factory=dict)
    outputs: tuple = ()  # formats this verb writes, when not every Blender exporter


_GEOMETRY = frozenset({"MESH", "CURVE", "SURFACE", "META", "FONT"})
VERBS = {v.name: v for v in (
    Verb("tessellate", "tessera.tessellate", "Smooth meshes with PN triangles or Phong, uniformly or for the camera",
         frozenset({"MESH"}), frozenset({"MESH"}), {"output": "NEW_OBJECT"}),
    Verb("tubes", "tessera.tubes", "Build tubes around curves, hair curves (and meshes' edges, when named)",
         frozenset({"CURVE", "CURVES", "MESH"}), frozenset({"CURVE", "CURVES"})),
    Verb("loop", "tessera.loop_subdivide", "Smooth triangle meshes with Loop subdivision",
         frozenset({"MESH"}), frozenset({"MESH"}), {"output": "NEW_OBJECT"}),
    Verb("surface", "tessera.surface_tessellate", "Turn NURBS and Bezier surface objects into meshes, to a tolerance",
         frozenset({"SURFACE"}), frozenset({"SURFACE"})),
    Verb("impostors", "tessera.impostor_bake", "Render objects from many directions with Cycles onto impostor cards",
         _GEOMETRY, _GEOMETRY, outputs=(".blend", ".glb")),
    Verb("terrain", "tessera.terrain_add",
         "Mesh height maps and elevation files (GeoTIFF, .hgt, .asc, .img, .vrt) for the scene camera"),
)}
_TERRAIN_BAKE = Verb("terrain", "tessera.terrain_bake", "Mesh a terrain again for the camera")
#: Operator options the command line sets itself or that need a window (or a view layer to hide things in).
_NOT_OPTIONS = {"output", "hide_source", "camera_source", "filepath", "tile_files", "source", "image_name"}


class Usage(Exception):
    """Bad arguments (exit code 2)."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise Usage(f"{self.prog}: {message}")


def _say(line):
    print(f"tessera: {line}", file=sys.stderr, flush=True)


def operator_settings(verb):
    """The settings of ``verb``'s operator a command line may set (`options.settable`)."""
    return settable(verb.operator, _NOT_OPTIONS | set(verb.fixed))


def terrain_frames(args):
    """The frames of ``--frames`` (None when not given); several need a per-frame output name."""
    frames = _frames(args.frames) if args.frames else None
    if frames is not None and len(frames) > 1 and not files.per_frame(args.out):
        raise Usage(f"{args.out}: several frames need {{frame}} or #### in the output name")
    return frames


def parser_for(verb):
    """The argparse parser of ``verb`` (a `Verb`), with its operator's settings as options."""
    p = _Parser(prog=f"blender -c tessera {verb.name}", description=verb.summary + ".", allow_abbrev=False)
    if verb.name == "terrain":
        p.add_argument("inputs", nargs="+", metavar="FILE",
                       help="height maps (the first is the map, the rest its neighbouring tiles, in one folder), and "
                            "at most one .blend: the scene whose camera the terrain is meshed for")
        p.add_argument("--frames", metavar="A-B", help="mesh for the camera at each frame from A to B (one output "
                                                       "per frame: put {frame} or #### in the output name)")
    else:
        p.add_argument("inputs", nargs="*", metavar="FILE",
                       help="a .blend to open and/or mesh files to import (OBJ, PLY, STL, glTF, USD, Alembic, FBX); "
                            "none: the file already open")
        p.add_argument("--objects", metavar="NAMES",
                       help="the objects to work on, comma-separated, * and ? as wildcards (default: every "
                            + "/".join(sorted(verb.default_kinds)).lower() + " object)")
    p.add_argument("-o", "--out", metavar="FILE", required=True,
                   help="where to write the results: .blend (the whole scene) or "
                        + ", ".join(verb.outputs or sorted(files.EXPORTERS))
                        + "; {object} in the name writes one file per source object")
    p.add_argument("--camera", metavar="NAME", help="the camera object to use as the scene camera")
    p.add_argument("--frame", type=int, metavar="N", help="the scene frame (for an animated camera)")
    p.add_argument("--json", nargs="?", const="-", metavar="FILE",
                   help="print a JSON summary as the last line of the output (or write it to FILE)")
    add_options(p, operator_settings(verb))
    return p


@dataclass
class Summary:
    """What a run did, for ``--json``."""

    verb: str
    ok: bool = False
    results: list = field(default_factory=list)  # {"source", "objects", "vertices", "faces", "seconds"}
    failures: list = field(default_factory=list)  # {"source", "error"}
    outputs: list = field(default_factory=list)
    seconds: float = 0.0


def _counts(objects):
    v = f = 0
    for ob in objects:
        if ob.type == "MESH":
            v, f = v + len(ob.data.vertices), f + len(ob.data.polygons)
    return v, f


def _run_operator(verb, kwargs, source, summary, edits=None):
    """Run ``verb``'s operator; returns the objects it added, or ``edits`` (the objects it changes) when given; None
    on failure (recorded in ``summary``)."""
    module, name = verb.operator.split(".")
    before = set(bpy.data.objects)
    t0 = time.perf_counter()
    try:
        getattr(getattr(bpy.ops, module), name)(**kwargs)
    except RuntimeError as err:  # the operator's report: what to change
        if stopping.requested:
            raise stopping.Stopped(stopping.message()) from err
        message = str(err).strip()
        message = message[len("Error: "):] if message.startswith("Error: ") else message
        summary.failures.append({"source": source, "error": message})
        _say(f"{source}: FAILED: {message}")
        return None
    made = edits if edits is not None else [ob for ob in bpy.data.objects if ob not in before]
    vertices, faces = _counts(made)
    seconds = time.perf_counter() - t0
    summary.results.append({"source": source, "objects": [ob.name for ob in made], "vertices": vertices,
                            "faces": faces, "seconds": round(seconds, 3)})
    _say(f"{source} -> {', '.join(ob.name for ob in made) or 'nothing'} ({vertices:,} vertices, {faces:,} faces) "
         f"in {seconds:.2f} s")
    return made


def split_patterns(text):
    """``"Tree*,Rock[,]1"`` -> ``["Tree*", "Rock[,]1"]``: commas separate, except inside ``[...]``."""
    return [s.strip() for s in re.split(r",(?![^\[]*\])", text) if s.strip()]


def targets(verb, patterns):
    """The source objects of a per-object verb: named by ``patterns`` (comma-separated wildcards) or by kind."""
    scene_objects = list(bpy.context.scene.objects)
    if not patterns:
        found = [ob for ob in scene_objects if ob.type in verb.default_kinds]
        if not found:
            raise Usage(f"Nothing to {verb.name}: the scene has no {'/'.join(sorted(verb.default_kinds)).lower()} "
                        "object (name others with --objects)")
        return found
    found = []
    for pattern in split_patterns(patterns):
        hits = [ob for ob in scene_objects if fnmatch.fnmatchcase(ob.name, pattern) and ob not in found]
        if not hits and not any(fnmatch.fnmatchcase(ob.name, pattern) for ob in found):
            names = ", ".join(ob.name for ob in scene_objects[:20]) or "none"
            raise Usage(f"No object in the scene is named {pattern!r} (objects: {names})")
        for ob in hits:
            if ob.type not in verb.kinds:
                raise Usage(f"{ob.name!r} is a {ob.type.lower()} object; {verb.name} takes "
                            f"{'/'.join(sorted(verb.kinds)).lower()} objects")
        found += hits
    return found


def _scene_settings(args):
    scene = bpy.context.scene
    if args.camera is not None:
        cam = scene.objects.get(args.camera)
        if cam is None or cam.type != "CAMERA":
            raise Usage(f"No camera object named {args.camera!r} in the scene")
        scene.camera = cam
    if args.frame is not None:
        scene.frame_set(args.frame)


def _frames(text):
    try:
        a, _, b = text.partition("-")
        first, last = int(a), int(b or a)
    except ValueError:
        raise Usage(f"--frames {text!r}: give A-B, whole numbers (or one frame)") from None
    if last < first:
        raise Usage(f"--frames {text!r}: the last frame comes before the first")
    return range(first, last + 1)


def _check_outputs(verb, args, per_object_count):
    try:
        files.check_output(args.out, verb.outputs or None)
    except files.FileProblem as err:
        raise Usage(str(err)) from err
    one_object_formats = {".glb"} if verb.name == "impostors" else set()
    if (files.extension(args.out) in one_object_formats and "{object}" not in args.out
            and per_object_count != 1):
        raise Usage(f"{args.out}: a {files.extension(args.out)} holds one impostor; put {{object}} in the name to "
                    "write one file per object")


def _write(verb, pattern, groups, outputs, frame=None):
    """Write the results into ``outputs`` (`files.Outputs`): ``groups`` is [(source name, objects)]; one file, or one
    per source with {object}."""
    if "{object}" in pattern:
        jobs = [(files.output_name(pattern, src, frame), objs) for src, objs in groups]
    else:
        jobs = [(files.output_name(pattern, None, frame), [ob for _, objs in groups for ob in objs])]
    for path, objects in jobs:
        if verb.name == "impostors" and files.extension(path) == ".glb":
            files.select_only(objects)
            outputs.write_with(path, lambda p: bpy.ops.tessera.impostor_export(filepath=p))
        else:
            outputs.write(path, objects)


def run_object_verb(verb, args, summary, outputs):
    kwargs = dict(chosen(args, operator_settings(verb)), **verb.fixed)
    files.read_inputs(args.inputs)
    _scene_settings(args)
    sources = targets(verb, args.objects)
    _check_outputs(verb, args, len(sources))
    groups = []
    for i, ob in enumerate(sources):
        _say(f"{verb.name} {i + 1}/{len(sources)}: {ob.name}")
        files.select_only([ob])
        made = _run_operator(verb, kwargs, ob.name, summary)
        if made is not None:
            groups.append((ob.name, made))
    if summary.failures:
        return EXIT_FAILED
    _write(verb, args.out, groups, outputs, args.frame)
    return EXIT_OK


def terrain_inputs(args):
    """The .blend files and the height maps (absolute paths) among a terrain's inputs; `Usage` for what cannot be."""
    blends = [p for p in args.inputs if files.extension(p) == ".blend"]
    maps = [os.path.abspath(p) for p in args.inputs if files.extension(p) != ".blend"]
    if not maps:
        raise Usage("Give a height map (PNG, TIFF/GeoTIFF, .hgt, .asc, .img, .vrt, EXR, .r16/.r32/.raw)")
    for m in maps:
        if os.path.isdir(m):
            raise Usage(f"{m}: is a folder; give a height map file")
        if not os.path.isfile(m):
            raise Usage(f"{m}: no such file")
    if any(os.path.dirname(m) != os.path.dirname(maps[0]) for m in maps[1:]):
        raise Usage("A terrain's tiles must lie in one folder")
    return blends, maps


def terrain_source(args, maps):
    """The terrain settings the operator gets for ``maps`` with ``args`` (the operator's defaults where not given),
    as an object with their names: what `terrain_data.read_source` reads."""
    values = {p.identifier: p.default for p in operator_rna(VERBS["terrain"].operator).properties
              if p.identifier != "rna_type" and not getattr(p, "array_length", 0) and p.type != "COLLECTION"}
    values.update(chosen(args, operator_settings(VERBS["terrain"])))
    values.update(filepath=maps[0], tile_files=";".join(os.path.basename(m) for m in maps[1:]), source="FILE")
    return SimpleNamespace(**values)


def run_terrain(verb, args, summary, outputs):
    kwargs = chosen(args, operator_settings(verb))
    frames = terrain_frames(args)
    _check_outputs(verb, args, 1)
    if "block" in kwargs:  # checked before anything is read
        try:
            block_tiles(kwargs["block"], (1, 1))
        except InvalidInputError as err:
            raise Usage(f"--block: {err}") from None
    blends, maps = terrain_inputs(args)
    try:
        files.read_inputs(blends)
    except files.FileProblem as err:
        raise Usage(str(err)) from err
    _scene_settings(args)
    kwargs.update(filepath=maps[0], tile_files=";".join(os.path.basename(m) for m in maps[1:]),
                  source="FILE", camera_source="SCENE")
    bake = {k: v for k, v in kwargs.items() if k in ("block", "void_index")}
    scene, source = bpy.context.scene, os.path.basename(maps[0])
    terrain = None
    for frame in frames or [args.frame]:
        if frame is not None:
            scene.frame_set(frame)
            _say(f"terrain: frame {frame}")
        if terrain is None:
            made = _run_operator(verb, kwargs, source, summary)
            if made is None:
                return EXIT_FAILED
            terrain = made[0]
        else:  # later frames: the same terrain (its analysis cached), meshed again for the camera
            files.select_only([terrain])
            if _run_operator(_TERRAIN_BAKE, bake, source, summary, edits=[terrain]) is None:
                return EXIT_FAILED
        summary.results[-1]["frame"] = frame
        _write(verb, args.out, [(source, [terrain])], outputs, frame)
    return EXIT_OK


def probe_outputs(args):
    """Refuse, before any work, an output or ``--json`` file that cannot be written (`files.probe_output`)."""
    files.probe_output(files.output_name(args.out, "object", 1))
    if args.json not in (None, "-"):
        files.probe_output(args.json)


def run(verb_name, argv):
    """Run one verb with its arguments; returns the exit code."""
    verb = VERBS[verb_name]
    summary = Summary(verb.name)
    t0 = time.perf_counter()
    args = parser_for(verb).parse_args(argv)  # Usage on bad arguments; SystemExit(0) for --help
    try:
        files.check_output(args.out, verb.outputs or None)  # a format this Blender writes: before any work
    except files.FileProblem as err:
        raise Usage(str(err)) from err
    probe_outputs(args)
    outputs = files.Outputs()
    try:
        code = (run_terrain if verb.name == "terrain" else run_object_verb)(verb, args, summary, outputs)
        if code == EXIT_OK:
            finish(args, summary, outputs, t0)
    except files.FileProblem as err:
        raise Usage(str(err)) from err
    finally:
        outputs.discard()  # what was not committed
        if not summary.ok:
            summary.seconds = round(time.perf_counter() - t0, 3)
            _summary_out(args, summary)
    return code


def finish(args, summary, outputs, t0):
    """Give the run's outputs their final names, the ``--json`` summary file first (when it cannot be written, no
    output is); then print the summary when it goes to the standard output."""
    summary.outputs = [p for pending in outputs.pending for p in pending.paths]
    summary.ok = not summary.failures and bool(summary.outputs)
    summary.seconds = round(time.perf_counter() - t0, 3)
    try:
        if args.json not in (None, "-"):
            _write_summary(args.json, summary)
    except BaseException:
        summary.ok = False
        raise
    for path in outputs.commit():
        _say(f"wrote {path}")
    if args.json == "-":
        print(json.dumps(asdict(summary)), flush=True)


def _write_summary(path, summary):
    """The summary as a file, whole or absent (`files.write_with`)."""
    text = json.dumps(asdict(summary)) + "\n"

    def write(partial):
        with open(partial, "w", encoding="utf-8") as f:
            f.write(text)

    files.write_with(path, write).commit()


def _summary_out(args, summary):
    """Print or write the summary of a run that failed (best effort: a summary that cannot be written is said)."""
    if not args.json:
        return
    if args.json == "-":
        print(json.dumps(asdict(summary)), flush=True)
        return
    try:
        _write_summary(args.json, summary)
    except (files.WriteFailed, OSError) as err:
        _say(f"the summary was not written either: {err}")

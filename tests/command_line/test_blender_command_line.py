"""``blender -c tessera`` through the callback the add-on registers (tier: blender): help, exit codes, bad arguments,
every output format read back by Blender's importers, failures that write nothing, ``--json``, and plans.

These run in the test process on the file already open (no input files, which would replace it); the command lines
with input files, separate processes and killed tasks are in `test_blender_command_line_processes.py`.
"""

import json
import os
import subprocess
import sys

import pytest

pytestmark = pytest.mark.blender


@pytest.fixture
def cli(addon_module):
    return addon_module("addon.command_line")


@pytest.fixture
def scene(clean_scene, bpy_module):
    bpy = bpy_module
    bpy.ops.mesh.primitive_monkey_add(location=(0, 0, 0))
    bpy.ops.mesh.primitive_cube_add(location=(3, 0, 0))
    return bpy


@pytest.fixture
def importing(scene):
    """The scene, put back as it was after a test that imports files: an importer may change the world (USD adds its
    dome light's environment to it) and the frame range, which later tests render with."""
    bpy = scene
    s = bpy.context.scene
    world = s.world
    saved = world.copy() if world is not None else None
    kept = (s.frame_start, s.frame_end, s.render.fps, s.unit_settings.scale_length)
    yield bpy
    s = bpy.context.scene
    s.frame_start, s.frame_end, s.render.fps, s.unit_settings.scale_length = kept
    if saved is not None:
        name = world.name
        s.world = saved
        bpy.data.worlds.remove(world)
        saved.name = name


def test_the_add_on_registers_the_command(cli):
    assert cli.COMMAND == "tessera" and len(cli._handles) == 1


def test_help_lists_every_verb_and_every_setting_with_its_tooltip(cli, bpy_module, capsys):
    assert cli.execute([]) == 2  # no verb: the usage, as a bad argument
    assert cli.execute(["--help"]) == 0
    out = capsys.readouterr().out
    for verb in ("tessellate", "tubes", "loop", "surface", "impostors", "terrain", "join", "plan"):
        assert f"  {verb}" in out
    assert cli.execute(["tessellate", "--help"]) == 0
    out = capsys.readouterr().out.replace("\n", " ")
    rna = bpy_module.ops.tessera.tessellate.get_rna_type()
    skipped = cli.verbs._NOT_OPTIONS | {"rna_type"}  # set by the command line itself, or needing a window
    shown = [p for p in rna.properties if p.identifier not in skipped and not p.is_hidden]
    assert len(shown) > 15
    words = " ".join(out.split())
    for p in shown:
        assert "--" + p.identifier.replace("_", "-") in out, p.identifier
        label = f"{p.name}: {' '.join(p.description.split())[:30]}" if p.description else p.name
        assert label in words, (p.identifier, label)  # the label the panels show, beside the flag
    assert "Target edge length on screen (0.5 to 100000; default 10)" in words
    for verb in ("tubes", "loop", "surface", "impostors", "terrain", "join", "plan"):
        assert cli.execute([verb, "--help"]) == 0, verb
    assert "--raw-width" in capsys.readouterr().out


@pytest.mark.parametrize("argv, says", [
    (["unfold", "-o", "x.obj"], "no verb 'unfold'"),
    (["tessellate", "--level"], "expected one argument"),
    (["tessellate", "-o", "x.obj", "--level", "0"], "outside 1 to 64"),
    (["loop", "-o", "x.obj", "--levels", "nan"], "'nan' is not an integer"),
    (["tessellate", "-o", "x.obj", "--level", "nan"], "nan is outside 1 to 64"),
    (["tessellate", "-o", "x.obj", "--edge-pixels", "nan"], "outside 0.5 to 100000"),
    (["tessellate", "-o", "x.obj", "--method", "bezier"], "'bezier' is not one of pn, phong"),
    (["tessellate", "-o", "x.obj", "--metrics", "projected,speed"], "'speed' is not one of"),
    (["tessellate", "--level", "2"], "the following arguments are required: -o/--out"),
    (["tessellate", "-o", "x.docx"], "cannot write .docx"),
    (["tessellate", "-o", "x.obj", "--objects", "Teapot"], "No object in the scene is named 'Teapot'"),
    (["tessellate", "-o", "x.obj", "--objects", "Cam*"], "'Camera' is a camera object; tessellate takes mesh"),
    (["impostors", "-o", "x.glb"], "put {object} in the name"),
    (["impostors", "-o", "x.obj"], "use one of .blend, .glb"),
    (["terrain", "-o", "x.obj", "missing.png"], "missing.png: no such file"),
    (["terrain", "-o", "x.obj", "a.png", "--frames", "3-1"], "the last frame comes before the first"),
    (["terrain", "-o", "x.obj", "--block", "0,0,2"], "give 4 values"),
    # the block is checked before the map is looked for
    (["terrain", "-o", "x.obj", "missing.png", "--block", "5,0,2,2"], "Block 5, 0 of a 2 x 2 split does not exist"),
    (["tessellate", os.sep, "-o", "x.obj"], ": is a folder; give a file"),
    (["join", "missing.blend", "-o", "x.obj"], "missing.blend: no such file"),
    (["join", os.sep, "-o", "x.obj"], ": is a folder; give a file"),
    (["plan", "tessellate", "missing.blend", "-o", "x.obj"], "missing.blend: no such file"),
    (["plan", "terrain", "a.png", "-o", "t.blend", "--blocks", "0x2"], "invalid blocks_arg value"),
    (["tessellate", "-o", "x.obj", "--no-such-setting"], "unrecognized arguments: --no-such-setting"),
])
def test_bad_arguments_exit_2_with_what_is_wrong_and_change_nothing(cli, scene, tmp_path, capsys, argv, says):
    bpy = scene
    bpy.ops.object.camera_add()
    objects = sorted(ob.name for ob in bpy.data.objects)
    os.chdir(tmp_path)
    assert cli.execute(argv) == 2
    err = " ".join(capsys.readouterr().err.split())
    assert says in err
    assert sorted(ob.name for ob in bpy.data.objects) == objects
    assert os.listdir(tmp_path) == []


def test_a_run_writes_its_results_and_a_json_summary(cli, scene, tmp_path, capsys):
    bpy = scene
    summary = tmp_path / "summary.json"
    code = cli.execute(["tessellate", "--objects", "Suz*", "--method", "phong", "--level", "3",
                        "-o", str(tmp_path / "monkey.ply"), "--json", str(summary)])
    assert code == 0
    made = bpy.data.objects["Suzanne.tessellated"]
    info = json.loads(summary.read_text())
    assert info["ok"] and info["failures"] == [] and info["outputs"] == [str(tmp_path / "monkey.ply")]
    assert len(made.data.polygons) > 968 * 9  # level 3 (fractional-even: more than 9 per triangle)
    assert info["results"] == [{"source": "Suzanne", "objects": ["Suzanne.tessellated"],
                                "faces": len(made.data.polygons),
                                "vertices": len(made.data.vertices), "seconds": info["results"][0]["seconds"]}]
    assert made.tessera.tessellate.method == "PHONG"  # the operator's own settings, stored as in the UI
    # --json alone: the summary is the last line of the output
    assert cli.execute(["loop", "--objects", "Cube", "--levels", "1", "-o", str(tmp_path / "cube.obj"),
                        "--json"]) == 0
    last = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert last["results"][0]["faces"] == 12 * 4
    assert sorted(os.listdir(tmp_path)) == ["cube.mtl", "cube.obj", "monkey.ply", "summary.json"]


FORMATS = (".blend", ".obj", ".ply", ".stl", ".glb", ".gltf", ".usdc", ".usda", ".abc", ".fbx")


@pytest.mark.parametrize("ext", FORMATS)
def test_every_output_format_is_written_whole_and_reads_back(cli, importing, tmp_path, ext):
    bpy = importing
    path = tmp_path / f"cube{ext}"
    assert cli.execute(["loop", "--objects", "Cube", "--levels", "2", "-o", str(path)]) == 0
    made = bpy.data.objects["Cube.loop"]
    faces = len(made.data.polygons)
    assert faces == 12 * 16
    left = sorted(n for n in os.listdir(tmp_path) if n.startswith("."))
    assert left == [] and path.stat().st_size > 0  # no partial file beside it
    # read back through Blender: the same triangles
    if ext == ".blend":
        with bpy.data.libraries.load(str(path)) as (src, dst):
            dst.objects = ["Cube.loop"]
        back = dst.objects
    else:
        files = cli.files
        before = set(bpy.data.objects)
        files.read_inputs_into_scene([str(path)])
        back = [ob for ob in bpy.data.objects if ob not in before and ob.type == "MESH"]
    assert len(back) == 1 and len(back[0].data.polygons) == faces


def test_one_file_per_object_and_a_failure_writes_nothing(cli, scene, tmp_path, capsys):
    bpy = scene
    assert cli.execute(["tessellate", "--level", "2", "-o", str(tmp_path / "{object}.glb"), "--json"]) == 0
    assert sorted(os.listdir(tmp_path)) == ["Cube.glb", "Suzanne.glb"]
    capsys.readouterr()
    empty = bpy.data.objects.new("Empty mesh", bpy.data.meshes.new("Empty mesh"))
    bpy.context.scene.collection.objects.link(empty)
    out = tmp_path / "again"
    code = cli.execute(["tessellate", "--objects", "Suzanne,Empty*,Cube", "-o", str(out / "{object}.glb"),
                        "--json"])
    captured = capsys.readouterr()
    assert code == 1
    info = json.loads(captured.out.strip().splitlines()[-1])
    assert not info["ok"] and [r["source"] for r in info["results"]] == ["Suzanne", "Cube"]  # the others still tried
    assert info["failures"] == [{"source": "Empty mesh", "error": "Mesh 'Empty mesh' has no faces to work on"}]
    assert "Empty mesh: FAILED: Mesh 'Empty mesh' has no faces to work on" in captured.err
    assert not out.exists() and info["outputs"] == []


def test_join_refuses_a_file_that_is_not_a_blend(cli, scene, tmp_path, capsys):
    fake = tmp_path / "notes.blend"
    fake.write_text("not a scene")
    assert cli.execute(["join", str(fake), "-o", str(tmp_path / "x.obj")]) == 2
    err = capsys.readouterr().err
    assert "notes.blend: is not a Blender file" in err and "Traceback" not in err
    assert os.listdir(tmp_path) == ["notes.blend"]


@pytest.mark.parametrize("case", ["parent is a file", "name is a folder", "json parent is a file"])
def test_an_output_that_cannot_be_written_exits_1_before_any_work(cli, scene, tmp_path, capsys, case):
    (tmp_path / "afile").write_text("x")
    (tmp_path / "cube.ply").mkdir()
    out, summary, says = str(tmp_path / "out.ply"), None, ""
    if case == "parent is a file":
        out, says = str(tmp_path / "afile" / "out.ply"), f"not written: {tmp_path / 'afile'} is a file, not a folder"
    elif case == "name is a folder":
        out, says = str(tmp_path / "cube.ply"), "cube.ply: not written: it is a folder; give a file name"
    else:
        summary, says = str(tmp_path / "afile" / "s.json"), "s.json: not written:"
    argv = ["tessellate", "--objects", "Cube", "--level", "2", "-o", out] + (["--json", summary] if summary else [])
    assert cli.execute(argv) == 1
    err = capsys.readouterr().err
    assert says in err and "Traceback" not in err
    assert "tessellate 1/1" not in err  # refused before the work
    assert sorted(os.listdir(tmp_path)) == ["afile", "cube.ply"] and os.listdir(tmp_path / "cube.ply") == []


def test_the_json_summary_is_written_before_the_outputs_are_named(cli, scene, tmp_path, capsys, monkeypatch):
    """When the summary cannot be written (checked at the start, it failed at the end), no output is named."""
    files = cli.files
    real = files.write_with

    def refuse_json(path, writer, expected=None):
        if path.endswith(".json"):
            raise files.failed(path, "no space left on the device")
        return real(path, writer, expected)

    monkeypatch.setattr(files, "write_with", refuse_json)
    code = cli.execute(["tessellate", "--objects", "Cube", "--level", "2", "-o", str(tmp_path / "cube.ply"),
                        "--json", str(tmp_path / "s.json")])
    err = capsys.readouterr().err
    assert code == 1 and "s.json: not written: no space left on the device" in err
    assert os.listdir(tmp_path) == []  # neither the output nor a partial file


def test_names_with_wildcards_and_commas_are_taken_literally(cli, scene, tmp_path):
    bpy = scene
    bpy.data.objects["Cube"].name = "Rock [a],b*"
    verbs = cli.verbs
    plan = cli.plan
    import glob

    pattern = glob.escape("Rock [a],b*").replace(",", "[,]")
    assert verbs.split_patterns(f"Suz*,{pattern}") == ["Suz*", pattern]
    found = verbs.targets(verbs.VERBS["tessellate"], pattern)
    assert [ob.name for ob in found] == ["Rock [a],b*"]
    assert plan is not None


def test_a_plan_has_one_task_per_object_whose_arguments_mean_the_same(cli, scene, tmp_path, capsys):
    bpy = scene
    bpy.data.objects["Cube"].name = "Box, large"
    assert cli.execute(["plan", "tessellate", "--method", "phong", "--metrics", "projected,silhouette",
                        "--level-mode", "adaptive", "--edge-pixels", "6.25", "--no-use-object-settings",
                        "-o", str(tmp_path / "out.glb")]) == 0
    tasks = json.loads(capsys.readouterr().out)["tasks"]
    assert [t["name"] for t in tasks] == ["tessellate Suzanne", "tessellate Box, large"]
    assert tasks[1]["outputs"] == [str(tmp_path / "out_Box__large.glb")]
    verbs = cli.verbs
    verb = verbs.VERBS["tessellate"]
    props = verbs.operator_settings(verb)
    for task in tasks:
        assert task["command"][:3] == ["blender", "-c", "tessera"] and task["command"][3:] == task["argv"]
        args = verbs.parser_for(verb).parse_args(task["argv"][1:])
        assert [ob.name for ob in verbs.targets(verb, args.objects)] == [task["name"].split(" ", 1)[1]]
        given = cli.options.chosen(args, props)
        assert given == {"method": "PHONG", "metrics": {"PROJECTED", "SILHOUETTE"}, "level_mode": "ADAPTIVE",
                         "edge_pixels": 6.25, "use_object_settings": False}


def test_every_setting_survives_the_plans_round_trip(cli, bpy_module):
    """Each setting, set away from its default, is written into a task's command line and parsed back equal."""
    verbs, plan = cli.verbs, cli.plan
    for verb in verbs.VERBS.values():
        props = verbs.operator_settings(verb)
        parser = verbs.parser_for(verb)
        args = parser.parse_args(["in.blend", "-o", "out.blend"])
        for p in props:
            if p.type == "BOOLEAN":
                value = not p.default
            elif p.type == "ENUM":
                items = [i.identifier for i in p.enum_items]
                value = set(items[:2]) if p.is_enum_flag else items[-1]
            elif p.type == "STRING":
                value = "a b;c"
            elif getattr(p, "array_length", 0):
                value = tuple(min(p.hard_max, p.hard_min + 1) for _ in range(p.array_length))
            elif p.type == "FLOAT":
                value = min(p.hard_max, max(p.hard_min, 0.1 + p.default * 1.5))
            else:
                value = min(p.hard_max, p.default + 1)
            setattr(args, p.identifier, value)
        argv = plan.task_argv(verb, args, props)
        back = parser.parse_args(argv[1:])
        for p in props:
            assert getattr(back, p.identifier) == getattr(args, p.identifier), (verb.name, p.identifier)


def test_stale_partial_files_of_dead_tasks_are_removed_and_live_ones_kept(cli, tmp_path):
    files = cli.files
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True).stdout.strip()
    host = files._host()
    stale = tmp_path / f".terrain.tessera-partial-{host}-{dead}.blend"
    stale_dir = tmp_path / f".scene.tessera-partial-{host}-{dead}"
    live = tmp_path / f".cube.tessera-partial-{host}-{os.getpid()}.obj"
    other_host = tmp_path / f".rock.tessera-partial-elsewhere-{dead}.obj"
    for p in (stale, live, other_host):
        p.write_bytes(b"half")
    stale_dir.mkdir()
    (stale_dir / "scene.bin").write_bytes(b"half")
    files.remove_stale_partials(str(tmp_path))
    assert sorted(os.listdir(tmp_path)) == sorted([live.name, other_host.name])


@pytest.mark.parametrize("verb, add, extra", [
    ("tubes", "curve.primitive_bezier_circle_add", ["--radius", "0.05", "--caps", "round"]),
    ("surface", "surface.primitive_nurbs_surface_sphere_add", ["--metrics", "tolerance", "--tolerance", "0.001"]),
    ("loop", "mesh.primitive_ico_sphere_add", ["--levels", "2"]),
    ("tessellate", "mesh.primitive_cylinder_add", ["--method", "pn", "--level", "4"]),
])
def test_each_verb_makes_its_geometry_from_blenders_own_primitives(cli, clean_scene, bpy_module, tmp_path, capsys,
                                                                    verb, add, extra):
    bpy = bpy_module
    module, name = add.split(".")
    getattr(getattr(bpy.ops, module), name)()
    source = bpy.context.active_object.name
    out = tmp_path / "out.glb"
    assert cli.execute([verb, *extra, "-o", str(out), "--json"]) == 0
    info = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    (result,) = info["results"]
    assert result["source"] == source and result["faces"] > 100
    made = bpy.data.objects[result["objects"][0]]
    assert made.type == "MESH" and len(made.data.polygons) == result["faces"]
    before = set(bpy.data.objects)
    cli.files.read_inputs_into_scene([str(out)])
    (back,) = [ob for ob in bpy.data.objects if ob not in before and ob.type == "MESH"]

    def triangles(me):  # glTF holds triangles: quads come back as two
        return sum(len(p.vertices) - 2 for p in me.polygons)

    assert triangles(back.data) == triangles(made.data)


def test_a_plan_goes_to_a_file_when_asked(cli, scene, tmp_path):
    to = tmp_path / "plan.json"
    assert cli.execute(["plan", "loop", "--levels", "1", "-o", str(tmp_path / "{object}.ply"), "--json", str(to)]) == 0
    tasks = json.loads(to.read_text())["tasks"]
    assert sorted(t["outputs"][0] for t in tasks) == [str(tmp_path / "Cube.ply"), str(tmp_path / "Suzanne.ply")]
    assert all("--json" not in t["argv"] for t in tasks)


#: Flags of other programs the docs show: Blender's own, and the bench scripts' (checked in their source).
BLENDER_FLAGS = {"--command", "--background", "--python", "--python-expr", "--version", "--enable-event-simulate",
                 "--help"}
TOOL_FLAGS = {"--run": "tools/bench_report.py", "--full": "bench/terrain.py"}


def test_the_docs_flamenco_job_type_is_the_one_plan_writes(cli):
    """The job type in the docs is `schedulers.flamenco_job_type`'s, its default plan aside."""
    import re
    from pathlib import Path

    page = (Path(__file__).resolve().parents[2] / "docs" / "command_line.md").read_text(encoding="utf-8")
    shown = page[page.index("```js\n") + 6:page.index("```", page.index("```js\n") + 6)]
    made = cli.schedulers.flamenco_job_type({"verb": "terrain", "steps": [], "tasks": []})
    made = re.sub(r"^// .*\n", "", made, flags=re.M)

    def without_default(text):
        return re.sub(r"default: .*?, *$", "default: …,", text, flags=re.M)

    assert without_default(shown) == without_default(made)


def test_every_flag_the_readme_and_the_docs_name_exists(cli):
    """A flag named in the README or a docs page is an option of a verb, of join or plan, Blender's own, or a bench
    script's: a renamed option cannot stay in the manual."""
    import re
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    ours = set()
    parsers = [cli.verbs.parser_for(v) for v in cli.verbs.VERBS.values()] + [cli.join_parser(), cli.plan_parser()]
    for parser in parsers:
        ours |= {flag for action in parser._actions for flag in action.option_strings}
    for flag, source in TOOL_FLAGS.items():
        assert f'"{flag}"' in (root / source).read_text(encoding="utf-8"), (flag, source)
    # the schedulers' own tools the docs show: their flags as their --help lists them
    import subprocess
    import sys

    openjd = Path(sys.executable).with_name("openjd")
    helps = subprocess.run([str(openjd), "run", "--help"], capture_output=True, text=True).stdout
    ours |= set(re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]+)", helps))
    assert "--run-dependencies" in ours
    pages = [root / "README.md", *sorted((root / "docs").glob("*.md"))]
    unknown = set()
    for page in pages:
        for flag in re.findall(r"(?:^|[\s`\"(])(--[a-z][a-z0-9-]+)", page.read_text(encoding="utf-8"), re.MULTILINE):
            if flag not in ours | BLENDER_FLAGS | set(TOOL_FLAGS):
                unknown.add((page.name, flag))
    assert not unknown, f"the docs name flags nothing has: {sorted(unknown)}"
    assert {"--edge-pixels", "--no-culling", "--blocks", "--name"} <= ours  # the parsers were read

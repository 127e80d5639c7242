"""``blender -c tessera`` as separate processes, as a farm runs it (tier: blender): the built extension installed in a
user folder of its own, ``blender`` on PATH: Debian's packaged Blender where it runs here (`make test` as root), the
``bpy`` module standing in for the executable elsewhere and under `make test-all` (`blender_cli.py`, with Blender's
registry of add-on commands).

- a terrain split by ``plan`` into 4 blocks (two frames of a camera path) and into 16 blocks, every task its own
  process, joined: exactly the mesh one process makes (positions bit for bit, the same triangles);
- impostors planned per object: the same atlases as one process baking both;
- the same plans as an Open Job Description job template, checked by ``openjd check`` (the model Deadline Cloud
  validates with) and run by ``openjd run``, step by step with its dependencies, and as a Slurm script submitted to a
  one-node cluster on localhost (`slurm_cluster`), one array job per step: the same meshes, nothing left running;
- a task stopped (SIGTERM, as farm managers send) or killed (SIGKILL) leaves no output file, and the next task in that
  folder removes what the killed one left; a killed task's render worker and job folder go with it.
"""

import json
import os
import signal
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
from blender_helpers import installed_blender, processes_naming
from tessera.tools.geotiff_files import write_geotiff

pytestmark = pytest.mark.blender
ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def blender(built_zips, tmp_path_factory):
    """``run(*args)``: ``blender ARGS`` in a process, with Tessera installed from the built zip: CompletedProcess."""
    return installed_blender(built_zips, tmp_path_factory.mktemp("cli_home"), [tmp_path_factory.getbasetemp()])


def _blend(path, body):
    """Write the .blend ``path`` made by the Python lines ``body`` (``bpy`` imported, an empty scene) in a process
    of its own: the test process's file is never replaced."""
    code = (f"import bpy\nbpy.ops.wm.read_homefile(use_empty=True)\n{body}\n"
            f"bpy.ops.wm.save_as_mainfile(filepath={str(path)!r})\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    return path


def _ok(proc):
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return proc


def _dem():
    """A 193 x 257 int16 DEM with a lake of no-data, as a GeoTIFF in metres."""
    y, x = np.mgrid[0:193, 0:257] / 64.0
    top = 900 + 300 * np.sin(3 * x) * np.cos(2 * y) + 60 * np.sin(11 * x * y) + 25 * np.cos(23 * x)
    top = np.round(top).astype(np.int16)
    top[80:90, 100:118] = -32768
    return top


@pytest.fixture(scope="module")
def shot(tmp_path_factory):
    """A folder with the DEM and a .blend whose camera flies over it (frames 1 and 2)."""
    folder = tmp_path_factory.mktemp("terrain_job")
    write_geotiff(str(folder / "dem.tif"), _dem(), spacing=(10.0, 10.0), nodata=-32768)
    _blend(folder / "shot.blend", """
cam = bpy.data.objects.new("Drone", bpy.data.cameras.new("Drone"))
bpy.context.scene.collection.objects.link(cam)
cam.data.clip_end = 10000.0
cam.rotation_euler = (1.1, 0.0, -0.6)
cam.location = (-900.0, -1300.0, 1500.0)
cam.keyframe_insert("location", frame=1)
cam.location = (-300.0, -1100.0, 1300.0)
cam.keyframe_insert("location", frame=2)
bpy.context.scene.camera = cam
bpy.context.scene.render.resolution_x, bpy.context.scene.render.resolution_y = 960, 540""")
    return folder


def _mesh_of(bpy, path):
    """(positions (n, 3) float32, triangles (m, 3)) of the one mesh object in the .blend ``path``."""
    with bpy.data.libraries.load(str(path)) as (src, dst):
        dst.objects = [n for n in src.objects]
    meshes = [ob for ob in dst.objects if ob.type == "MESH"]
    assert len(meshes) == 1, [ob.name for ob in dst.objects]
    me = meshes[0].data
    pos = np.empty(len(me.vertices) * 3, np.float32)
    corners = np.empty(len(me.loops), np.int32)
    if len(me.vertices):  # a block the camera does not see is an empty mesh, without a position attribute
        me.attributes["position"].data.foreach_get("vector", pos)
        me.attributes[".corner_vert"].data.foreach_get("value", corners)
    for ob in dst.objects:
        data = ob.data
        bpy.data.objects.remove(ob)
        if data is not None and data.users == 0:
            getattr(bpy.data, "meshes" if isinstance(data, bpy.types.Mesh) else "cameras").remove(data)
    return pos.reshape(-1, 3), corners.reshape(-1, 3)


def _same_mesh(a, b):
    """Meshes ``a`` and ``b`` (from `_mesh_of`) are the same: the same vertices bit for bit (no two alike) and the same
    triangles (as triples of positions, orientation kept)."""
    (pa, ta), (pb, tb) = a, b
    assert len(pa) == len(pb) and len(ta) == len(tb)
    assert np.array_equal(np.unique(pa, axis=0), np.unique(pb, axis=0)) and len(np.unique(pa, axis=0)) == len(pa)

    def tris(p, t):
        keys = [tuple(map(tuple, tri)) for tri in p[t]]  # each rotated to start at its smallest corner: winding kept
        return {min(k[i:] + k[:i] for i in range(3)) for k in keys}

    assert tris(pa, ta) == tris(pb, tb)


def _impostor_pixels(bpy, path, name):
    """The impostor images of object ``name`` in the .blend ``path``: {image name: pixels}."""
    with bpy.data.libraries.load(str(path)) as (src, dst):
        dst.images = [n for n in src.images if n.startswith(f"{name} impostor")]
    out = {im.name.rsplit(".", 1)[0] if im.name[-4:-3] == "." else im.name: np.array(im.pixels[:], np.float32)
           for im in dst.images}
    for im in dst.images:
        bpy.data.images.remove(im)
    return out


def _run_plan(blender, plan):
    """Run the plan's tasks as a farm would: the independent ones two at a time, each join after its blocks."""
    tasks = plan["tasks"]
    done = {}
    with ThreadPoolExecutor(2) as pool:
        while len(done) < len(tasks):
            ready = [t for t in tasks if t["name"] not in done and all(a in done for a in t["after"])]
            assert ready, "the plan's dependencies form a cycle"
            for task, proc in zip(ready, pool.map(lambda t: blender("-c", "tessera", *t["argv"]), ready), strict=True):
                _ok(proc)
                done[task["name"]] = proc
                for out in task["outputs"]:
                    assert os.path.isfile(out), (task["name"], out)
    return done


@pytest.mark.parametrize("blocks, frames", [("2x2", "1-2"), ("4x4", "2-2")])
def test_a_terrain_split_into_farm_tasks_joins_into_the_single_process_mesh(blender, shot, bpy_module, tmp_path,
                                                                            blocks, frames):
    bpy = bpy_module
    args = [shot / "dem.tif", shot / "shot.blend", "--tile-size", "16", "--levels", "fractional", "--epsilon", "1.5",
            "--frames", frames]
    single = _ok(blender("-c", "tessera", "terrain", *args, "-o", tmp_path / "single" / "terrain_#.blend",
                         "--json"))
    summary = json.loads(single.stdout.strip().splitlines()[-1])
    first, last = (int(f) for f in frames.split("-"))
    assert summary["ok"] and [r["frame"] for r in summary["results"]] == list(range(first, last + 1))
    proc = _ok(blender("-c", "tessera", "plan", "terrain", *args, "--blocks", blocks,
                       "-o", tmp_path / "farm" / "terrain_#.blend"))
    plan = json.loads(proc.stdout[proc.stdout.index("{"):])
    cols, rows = (int(v) for v in blocks.split("x"))
    n_frames = last - first + 1
    assert len(plan["tasks"]) == n_frames * (cols * rows + 1)
    assert all(t["command"][:3] == ["blender", "-c", "tessera"] for t in plan["tasks"])
    # the lake's voids were found once, when the plan was made, for every block task to read
    index = tmp_path / "farm" / "terrain.tessera-voids"
    blocks_argv = [t["argv"] for t in plan["tasks"] if t["step"] == "Blocks"]
    assert index.is_file() and all(a[a.index("--void-index") + 1] == str(index) for a in blocks_argv)
    _run_plan(blender, plan)
    for frame in range(first, last + 1):
        whole = _mesh_of(bpy, tmp_path / "single" / f"terrain_{frame}.blend")
        joined = _mesh_of(bpy, tmp_path / "farm" / f"terrain_{frame}.blend")
        assert len(whole[1]) > 2000
        _same_mesh(whole, joined)
        blocks_tris = sum(len(_mesh_of(bpy, p)[1]) for p in (tmp_path / "farm").glob(f"terrain_{frame}_b*-*.blend"))
        assert blocks_tris == len(whole[1])  # every triangle made by exactly one block
    assert not [n for n in os.listdir(tmp_path / "farm") if n.startswith(".")]


def test_impostors_planned_per_object_bake_the_atlases_of_one_process(blender, bpy_module, tmp_path):
    bpy = bpy_module
    _blend(tmp_path / "props.blend", """
bpy.ops.mesh.primitive_cube_add(location=(0, 0, 0))
bpy.ops.mesh.primitive_ico_sphere_add(location=(3, 0, 0), subdivisions=2)
bpy.ops.object.light_add(type="SUN", location=(0, 0, 5))""")
    opts = ["--grid", "2", "--tile", "16", "--samples", "2"]
    _ok(blender("-c", "tessera", "impostors", tmp_path / "props.blend", *opts,
                "-o", tmp_path / "one" / "{object}.blend"))
    proc = _ok(blender("-c", "tessera", "plan", "impostors", tmp_path / "props.blend", *opts,
                       "-o", tmp_path / "farm" / "{object}.blend"))
    plan = json.loads(proc.stdout[proc.stdout.index("{"):])
    assert sorted(t["name"] for t in plan["tasks"]) == ["impostors Cube", "impostors Icosphere"]
    _run_plan(blender, plan)
    for name in ("Cube", "Icosphere"):
        images = [_impostor_pixels(bpy, tmp_path / folder / f"{name}.blend", name) for folder in ("one", "farm")]
        assert len(images[0]) == 3 and images[0].keys() == images[1].keys()  # colour, normal, depth
        for key in images[0]:
            assert np.array_equal(images[0][key], images[1][key]), key
            assert images[0][key].max() > 0


def _openjd(*args, env=None, cwd=None):
    """``openjd ARGS`` (the OpenJD reference CLI of this venv) in a process: CompletedProcess."""
    exe = Path(sys.executable).with_name("openjd")
    if not exe.exists():
        pytest.skip("openjd-cli is not installed (requirements)")
    return subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True, timeout=900, env=env, cwd=cwd)


FARM_ARGS = ["--tile-size", "16", "--epsilon", "1.5", "--frames", "1-2"]


@pytest.fixture(scope="module")
def single(blender, shot, tmp_path_factory):
    """The shot's terrain for frames 1 and 2 by one process, with `FARM_ARGS`: its folder (terrain_1, terrain_2)."""
    out = tmp_path_factory.mktemp("single")
    _ok(blender("-c", "tessera", "terrain", shot / "dem.tif", shot / "shot.blend", *FARM_ARGS,
                "-o", out / "terrain_#.blend"))
    return out


@pytest.mark.farm
def test_openjd_runs_the_terrain_plan_into_the_single_process_meshes(blender, shot, single, bpy_module, tmp_path):
    """``plan --format openjd``: a job template with a Blocks step (frames times blocks) and a Join step after it,
    valid for Open Job Description's model, run by its reference runner: every frame joins into the mesh one process
    makes."""
    bpy = bpy_module
    args = [shot / "dem.tif", shot / "shot.blend", *FARM_ARGS]
    template = tmp_path / "terrain.json"
    _ok(blender("-c", "tessera", "plan", "terrain", *args, "--blocks", "2x2", "--format", "openjd",
                "-o", tmp_path / "farm" / "terrain_#.blend", "--json", template))
    job = json.loads(template.read_text())
    assert [s["name"] for s in job["steps"]] == ["Blocks", "Join"]
    blocks = job["steps"][0]["parameterSpace"]
    assert blocks["combination"] == "Frame * (Block, Part)"
    assert {d["name"]: d["range"] for d in blocks["taskParameterDefinitions"]}["Frame"] == [1, 2]
    check = _openjd("check", template)
    assert check.returncode == 0, check.stdout + check.stderr
    sessions = tmp_path / "sessions"  # OpenJD's session folders where the packaged Blender's system sees them
    sessions.mkdir()
    run = _openjd("run", template, "--step", "Join", "--run-dependencies", env=dict(blender.env, TMPDIR=str(sessions)),
                  cwd=tmp_path)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    for frame in (1, 2):
        whole = _mesh_of(bpy, single / f"terrain_{frame}.blend")
        _same_mesh(whole, _mesh_of(bpy, tmp_path / "farm" / f"terrain_{frame}.blend"))
    assert len(list((tmp_path / "farm").glob("terrain_*_b*-*.blend"))) == 8
    assert not [n for n in os.listdir(tmp_path / "farm") if n.startswith(".")]


@pytest.mark.farm
def test_slurm_runs_the_terrain_plan_into_the_single_process_meshes(blender, shot, single, bpy_module, tmp_path):
    """``plan --format slurm``: the script submits the Blocks array job and the Join array job after it (afterok) to a
    real slurmctld and slurmd. A block task is pre-empted mid-way (``scontrol requeue``: Slurm stops it and runs it
    again); every job completes, every frame joins into the mesh one process makes, no partial file is left, and the
    cluster stops with nothing left running."""
    import slurm_cluster

    why = slurm_cluster.missing()
    if why:
        pytest.skip(why)
    bpy = bpy_module
    args = [shot / "dem.tif", shot / "shot.blend", *FARM_ARGS]
    script = tmp_path / "terrain.sh"
    _ok(blender("-c", "tessera", "plan", "terrain", *args, "--blocks", "2x2", "--format", "slurm",
                "-o", tmp_path / "farm" / "terrain_#.blend", "--json", script))
    cluster = slurm_cluster.start(tmp_path / "slurm")
    try:
        env = dict(blender.env, SLURM_CONF=cluster.env["SLURM_CONF"])  # jobs see the submitter's PATH: its blender
        submitted = cluster.run("bash", script, cwd=tmp_path, env=env)
        assert submitted.returncode == 0, submitted.stdout + submitted.stderr
        assert "Blocks: job" in submitted.stdout and "Join: job" in submitted.stdout
        victim = cluster.running()
        time.sleep(1.0)  # Blender is starting: the task is under way (a block takes about 2.5 s here)
        requeued = cluster.run("scontrol", "requeue", victim)
        assert requeued.returncode == 0, requeued.stdout + requeued.stderr
        cluster.release(victim)
        states = cluster.wait_idle()
        restarts = cluster.restarts()
    finally:
        cluster.stop()
    assert cluster.left() == []
    logs = "".join(p.read_text(errors="replace")[-800:] for p in tmp_path.glob("slurm-*.out"))
    assert states == ["COMPLETED"] * 10, (states, logs)  # 8 blocks, 2 joins
    assert restarts.get(victim) == 1, (victim, restarts)  # the pre-empted task ran again
    for frame in (1, 2):
        whole = _mesh_of(bpy, single / f"terrain_{frame}.blend")
        _same_mesh(whole, _mesh_of(bpy, tmp_path / "farm" / f"terrain_{frame}.blend"))
    assert not [n for n in os.listdir(tmp_path / "farm") if n.startswith(".")]


@pytest.mark.farm
def test_every_plan_format_carries_the_same_command_lines(blender, bpy_module, tmp_path):
    """Impostors for three objects in every format: OpenJD's template (checked by ``openjd check`` and run by ``openjd
    run``: the atlases one process bakes) has one task per object, the Slurm script one array task per object with the
    JSON plan's command line, the Flamenco job type holds the plan itself."""
    _blend(tmp_path / "three.blend", """
for i in range(3):
    bpy.ops.mesh.primitive_cube_add(location=(3 * i, 0, 0))
bpy.ops.object.light_add(type="SUN", location=(0, 0, 5))""")
    opts = ["--grid", "2", "--tile", "16", "--samples", "2"]
    plans = {}
    for fmt in ("json", "openjd", "slurm", "flamenco"):
        out = tmp_path / f"plan.{fmt}"
        _ok(blender("-c", "tessera", "plan", "impostors", tmp_path / "three.blend", *opts, "--format", fmt,
                    "-o", tmp_path / "farm" / "{object}.blend", "--json", out))
        plans[fmt] = out.read_text()
    plan = json.loads(plans["json"])
    assert [t["params"]["Object"] for t in plan["tasks"]] == ["Cube", "Cube.001", "Cube.002"]
    job = json.loads(plans["openjd"])
    (step,) = job["steps"]
    assert step["parameterSpace"]["taskParameterDefinitions"] == [
        {"name": "Object", "type": "STRING", "range": ["Cube", "Cube.001", "Cube.002"]}]
    words = step["script"]["actions"]["onRun"]["args"]
    filled = [w.replace("{{Task.Param.Object}}", "Cube.001") for w in words]
    assert filled == ["-c", "tessera"] + plan["tasks"][1]["argv"]
    check = _openjd("check", tmp_path / "plan.openjd")
    assert check.returncode == 0, check.stdout + check.stderr
    sessions = tmp_path / "sessions"
    sessions.mkdir()
    run = _openjd("run", tmp_path / "plan.openjd", "--step", "Objects", env=dict(blender.env, TMPDIR=str(sessions)),
                  cwd=tmp_path)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    _ok(blender("-c", "tessera", "impostors", tmp_path / "three.blend", *opts,
                "-o", tmp_path / "one" / "{object}.blend"))
    for task in plan["tasks"]:  # the outputs the plan names (Cube.001 -> Cube_001.blend)
        name, farm_file = task["params"]["Object"], Path(task["outputs"][0])
        farm = _impostor_pixels(bpy_module, farm_file, name)
        one = _impostor_pixels(bpy_module, tmp_path / "one" / farm_file.name, name)
        assert farm.keys() == one.keys() and len(farm) == 3
        assert all(np.array_equal(farm[k], one[k]) for k in farm)
    import shlex

    script = plans["slurm"]
    for i, task in enumerate(plan["tasks"]):
        assert f"Objects:{i}) exec \"$blender\" {shlex.join(['-c', 'tessera', *task['argv']])} ;;" in script
    assert "--array=0-2" in script and "afterok" not in script  # one step, nothing to wait for
    js = plans["flamenco"]
    default = js[js.index("default: ") + len("default: "):js.index(",\n", js.index("default: "))]
    assert json.loads(json.loads(default)) == plan


@pytest.fixture(scope="module")
def heavy(tmp_path_factory):
    """A .blend with a dense mesh that takes Loop subdivision seconds."""
    return _blend(tmp_path_factory.mktemp("heavy") / "grid.blend",
                  "bpy.ops.mesh.primitive_grid_add(x_subdivisions=200, y_subdivisions=200)")


def test_a_stopped_task_leaves_no_file(blender, heavy, tmp_path):
    out = tmp_path / "out"
    proc = blender.start("-c", "tessera", "loop", heavy, "--levels", "3", "-o", out / "grid.ply")
    for line in proc.stderr:  # the work has started
        if line.startswith("tessera: loop 1/1"):
            break
    time.sleep(0.5)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 1, err[-2000:]
    assert "stopped by signal" in err
    assert not out.exists() or os.listdir(out) == []


def test_a_killed_task_leaves_no_output_and_the_next_task_clears_its_partial_file(blender, heavy, tmp_path):
    out = tmp_path / "out"
    proc = blender.start("-c", "tessera", "tessellate", heavy, "--level", "6", "--spacing", "equal",
                         "-o", out / "grid.obj")
    partial = []
    while proc.poll() is None and not partial:
        partial = [n for n in (os.listdir(out) if out.exists() else []) if ".tessera-partial-" in n]
        time.sleep(0.005)
    proc.kill()
    proc.communicate(timeout=60)
    assert partial, "the task finished before its output was being written"
    assert not (out / "grid.obj").exists()  # killed while writing: the file asked for is not there
    assert sorted(os.listdir(out)) == partial  # only the hidden partial folder
    _ok(blender("-c", "tessera", "loop", heavy, "--levels", "1", "-o", out / "other.ply"))
    assert sorted(os.listdir(out)) == ["other.ply"]


def test_a_killed_task_takes_its_render_worker_and_job_folder_with_it(blender, bpy_module, tmp_path):
    """SIGKILL of an impostors task (a farm's pre-emption): within 5 s no worker renders on and no job folder stays."""
    _blend(tmp_path / "prop.blend", "bpy.ops.mesh.primitive_monkey_add()")
    temp = tmp_path / "temp"
    temp.mkdir()
    proc = subprocess.Popen(["blender", "-c", "tessera", "impostors", str(tmp_path / "prop.blend"), "--grid", "16",
                             "--tile", "256", "--samples", "512", "-o", str(tmp_path / "prop.blend.out.blend")],
                            env=dict(blender.env, TMPDIR=str(temp)), stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, cwd=tmp_path)
    deadline, workers, folders = time.monotonic() + 120, [], []
    while time.monotonic() < deadline and not workers:
        folders = [temp / n for n in os.listdir(temp) if n.startswith("tessera-impostor-")]
        workers = [p for f in folders for p in processes_naming(f"{f}/job.json") if p != proc.pid]
        time.sleep(0.05)
    assert workers, "the task started no render worker"
    time.sleep(1.0)  # rendering
    proc.kill()
    proc.wait(timeout=30)
    deadline = time.monotonic() + 5.0
    while time.monotonic() < deadline and (any(processes_naming(f"{f}/job.json") for f in folders)
                                           or any(f.exists() for f in folders)):
        time.sleep(0.05)
    assert not any(processes_naming(f"{f}/job.json") for f in folders), "a render worker outlived its task"
    assert not any(f.exists() for f in folders), "the job folder outlived its task"


def test_a_task_stopped_while_the_gltf_exporter_writes_ends_in_one_sentence(blender, heavy, tmp_path):
    """SIGTERM while Blender's glTF exporter (Python) runs: the stop waits for it, then nothing is written and no
    exporter traceback is printed."""
    out = tmp_path / "out"
    proc = blender.start("-c", "tessera", "tessellate", heavy, "--level", "3", "-o", out / "grid.glb")
    for line in proc.stderr:  # the mesh is made; the exporter starts now
        if " -> " in line:
            break
    time.sleep(0.3)
    assert proc.poll() is None, "the task ended before it could be stopped"
    proc.send_signal(signal.SIGTERM)
    stdout, err = proc.communicate(timeout=300)
    said = stdout + err
    assert proc.returncode == 1, said[-3000:]
    assert "tessera: stopped by signal 15; nothing was written" in said
    assert "Traceback" not in said and "wrote " not in said
    assert not out.exists() or os.listdir(out) == []

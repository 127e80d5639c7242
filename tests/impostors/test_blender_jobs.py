"""Background renders as jobs (tier: blender): a size check before anything starts, a worker that returns at once and
reports its progress and device, cancel that leaves nothing, folders removed when read and when stale, failures told
once with a back-off, the redo panel reusing what did not change, bakes that survive save and reload bit for bit, and
linked data refused."""

import os
import re
import subprocess
import sys
import time

import numpy as np
import pytest
from blender_helpers import UiOperator, processes_naming
from test_blender_bake import baked_box

pytestmark = pytest.mark.blender


def _box(bpy):
    bpy.ops.mesh.primitive_cube_add(size=1.0, scale=(2.0, 0.6, 0.4))
    return bpy.context.active_object


def _tessera_folders():
    import tempfile

    root = tempfile.gettempdir()
    return {n for n in os.listdir(root) if n.startswith(("tessera-impostor-", "tessera-board-"))}


def test_a_bake_too_large_is_refused_with_its_sizes_before_anything_starts(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    _box(bpy)
    before = _tessera_folders()
    with pytest.raises(RuntimeError) as err:
        bpy.ops.tessera.impostor_bake(grid=32, tile=2048)
    message = str(err.value)
    assert "65,536 x 65,536 texels" in message and "1,024 views of 2048 x 2048" in message, message
    assert "fewer Views or a smaller View Size" in message
    assert _tessera_folders() == before  # refused before a job (folder, worker) was started
    assert not addon_module("addon.render_jobs").open_folders()


def test_an_atlas_job_returns_at_once_reports_progress_and_device_and_leaves_no_folder(clean_scene, bpy_module,
                                                                                     addon_module):
    bpy = bpy_module
    bake = addon_module("addon.impostors.bake")
    jobs = addon_module("addon.render_jobs")
    box = _box(bpy)
    aj = bake.start_atlas(box, grid=2, tile=16, samples=1)
    assert os.path.isdir(aj.job.folder) and aj.job.folder in jobs.open_folders()
    lines = []
    aj.job.wait(lines.append, "Baking impostor views", timeout=300)
    assert lines[-1] == "Tessera: Baking impostor views 4/4" and aj.job.progress() == 4
    assert aj.job.device() == "CPU"  # no GPU is configured here: the worker says where it rendered
    atlas = bake.read_atlas(aj)
    assert atlas.colour.shape == (32, 32, 4) and (atlas.colour[..., 3] > 0.5).any()
    assert not os.path.exists(aj.job.folder) and aj.job.folder not in jobs.open_folders()


def test_a_gpu_asked_for_where_there_is_none_says_why_it_rendered_on_the_cpu(clean_scene, bpy_module, addon_module):
    bake = addon_module("addon.impostors.bake")
    aj = bake.start_atlas(_box(bpy_module), grid=1, tile=8, samples=1,
                          device={"type": "CUDA", "devices": [], "gpu": True})
    aj.job.wait(lambda line: None, "Baking impostor views", timeout=300)
    bake.read_atlas(aj)
    assert aj.job.device() == "CPU, because no GPU was found (Cycles sees no CUDA device)"


@pytest.mark.parametrize("case", ["empty curve", "loose points", "NaN vertex"])
def test_an_object_that_renders_nothing_or_garbage_is_refused_before_a_worker_starts(clean_scene, bpy_module,
                                                                                     addon_module, case):
    bpy = bpy_module
    if case == "empty curve":
        ob = bpy.data.objects.new("Thing", bpy.data.curves.new("Thing", "CURVE"))
        says = "'Thing' has no faces to render"
    else:
        me = bpy.data.meshes.new("Thing")
        nan = float("nan")
        if case == "loose points":
            me.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [])
            says = "'Thing' has no faces to render"
        else:
            me.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0), (nan, 0, 1)], [], [(0, 1, 2), (1, 2, 3)])
            says = "'Thing' has 1 vertices that are not numbers (NaN or infinite)"
        ob = bpy.data.objects.new("Thing", me)
    bpy.context.scene.collection.objects.link(ob)
    bpy.ops.object.select_all(action="DESELECT")
    ob.select_set(True)
    bpy.context.view_layer.objects.active = ob
    before = _tessera_folders()
    objects = set(bpy.data.objects)
    with pytest.raises(RuntimeError) as err:
        bpy.ops.tessera.impostor_bake(grid=2, tile=16, samples=1)
    assert says in str(err.value) and "Tessera failed" not in str(err.value)
    assert set(bpy.data.objects) == objects and _tessera_folders() == before
    # the live board of it: refused once, told in its panel, asked again only after a back-off
    live = addon_module("addon.impostors.live")
    preview = addon_module("addon.impostors.preview")
    manager = live.NailboardManager(preview._request)
    board = manager.update(ob, (0.0, -8.0, 1.0), 400, 0.8)
    assert says in board.failed and board.pending is None and board.retry_at > time.monotonic()
    assert manager.update(ob, (0.0, -8.0, 1.0), 400, 0.8).failures == 1  # not asked again at once


def test_cancel_stops_the_worker_and_leaves_nothing(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    bake = addon_module("addon.impostors.bake")
    aj = bake.start_atlas(_box(bpy), grid=4, tile=64, samples=256)
    aj.job.cancel()
    assert aj.job.process.poll() is not None and not os.path.exists(aj.job.folder)
    assert not addon_module("addon.render_jobs").open_folders()


def test_the_users_render_device_goes_to_the_worker(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    jobs = addon_module("addon.render_jobs")
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "GPU"
    device = jobs.render_device()
    prefs = bpy.context.preferences.addons["cycles"].preferences
    assert device["type"] == prefs.compute_device_type
    assert device["gpu"] == (prefs.compute_device_type != "NONE")  # a GPU scene renders on the CPU without one
    scene.cycles.device = "CPU"
    assert not jobs.render_device()["gpu"]


def test_stale_folders_are_removed_by_name_owner_and_age(tmp_path, addon_module):
    jobs = addon_module("addon.render_jobs")
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    now = time.time()

    def folder(name, owner, age):
        path = tmp_path / name
        path.mkdir()
        (path / "view.exr").write_bytes(b"x")
        if owner is not None:
            (path / "owner.pid").write_text(str(owner))
        os.utime(path, (now - age, now - age))
        return path

    orphan = folder("tessera-impostor-orphan", dead.pid, 120)
    young = folder("tessera-board-young", dead.pid, 5)  # its process may have just died: kept a while
    mine = folder("tessera-board-mine", os.getpid(), 120)  # a live process owns it
    ancient = folder("tessera-board-ancient", os.getpid(), 3 * 24 * 3600)
    other = folder("tessera-tests-other", dead.pid, 3 * 24 * 3600)  # not a kind of ours
    removed = jobs.remove_stale_folders(str(tmp_path), now)
    assert sorted(removed) == sorted([str(orphan), str(ancient)])
    assert young.exists() and mine.exists() and other.exists() and not orphan.exists()


def test_a_failed_board_is_told_once_and_asked_again_after_a_back_off(clean_scene, bpy_module, addon_module,
                                                                     monkeypatch):
    bpy = bpy_module
    live_mod = addon_module("addon.impostors.live")
    board = addon_module("kernels.impostors.board")
    TesseraError = addon_module("kernels.common.errors").TesseraError  # noqa: N806 - the add-on's own class

    class FailedJob:
        def __init__(self, setup):
            self.setup = setup

        def done(self):
            return True

        def result(self):
            raise TesseraError("Rendering the board failed (exit 1): simulated")

        def cancel(self):
            pass

    asked = []

    def request(ob, eye, res_screen, fov):
        asked.append(eye)
        return FailedJob(board.board_setup(np.full(3, -1.0), np.ones(3), eye, res_screen, fov))

    clock = [1000.0]
    monkeypatch.setattr(live_mod.time, "monotonic", lambda: clock[0])
    m = live_mod.NailboardManager(request)
    ob = _box(bpy)
    eye = np.array([0.0, -6.0, 1.0])
    for _ in range(50):  # fifty frames: one request, one failure, no exception
        live = m.update(ob, eye, 600, np.radians(50))
    assert len(asked) == 1 and live.failures == 1 and live.state.startswith("Failed")
    clock[0] += live_mod.RETRY_S + 0.1
    m.update(ob, eye, 600, np.radians(50))
    m.update(ob, eye, 600, np.radians(50))
    assert len(asked) == 2 and live.failures == 2  # asked again after the back-off, which then doubles
    assert live.retry_at - clock[0] == pytest.approx(2 * live_mod.RETRY_S)


def test_the_redo_panel_renders_again_only_when_the_render_changes(clean_scene, bpy_module, addon_module,
                                                                 monkeypatch):
    bpy = bpy_module
    bake = addon_module("addon.impostors.bake")
    started = []
    real = bake.start_worker
    monkeypatch.setattr(bake, "start_worker", lambda *a: started.append(1) or real(*a))
    box = _box(bpy)
    for settings in ({}, {"dilation": 0, "blend": False}, {"samples": 2}):
        bpy.context.view_layer.objects.active = box
        assert bpy.ops.tessera.impostor_bake(grid=2, tile=16, samples=settings.pop("samples", 1),
                                             **settings) == {"FINISHED"}
    assert len(started) == 2  # Dilation and Blend Views reuse the views; Samples renders again
    bpy.context.view_layer.objects.active = box
    # invoked where there is no window (background mode, the bpy module): to the end, as a script runs it
    assert bpy.ops.tessera.impostor_bake("INVOKE_DEFAULT", grid=2, tile=16, samples=3) == {"FINISHED"}
    assert len(started) == 3


def _pixels(image):
    px = np.empty(image.size[0] * image.size[1] * 4, np.float32)
    image.pixels.foreach_get(px)
    return px


def test_what_tessera_makes_survives_save_and_reload_bit_for_bit(clean_scene, bpy_module, tmp_path):
    bpy = bpy_module
    _, _, card = baked_box(bpy, tile=16)
    names = sorted({n.image.name for n in card.data.materials[0].node_tree.nodes if getattr(n, "image", None)})
    known = set(bpy.data.images.keys())
    assert bpy.ops.tessera.vector_field_texture(width=32, height=32) == {"FINISHED"}
    names += sorted(n for n in set(bpy.data.images.keys()) - known if bpy.data.images[n].type == "IMAGE")
    assert len(names) == 4  # colour, normal and depth atlases; the texture
    before = {n: _pixels(bpy.data.images[n]) for n in names}
    path = str(tmp_path / "made.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    bpy.ops.wm.open_mainfile(filepath=path)
    for name, px in before.items():
        image = bpy.data.images.get(name)
        assert image is not None, f"{name} was lost"
        assert _pixels(image).tobytes() == px.tobytes(), name


def test_linked_data_is_refused_by_name(clean_scene, bpy_module, tmp_path):
    bpy = bpy_module
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=1)
    source = bpy.context.active_object
    source.name = source.data.name = "Rock"
    library = str(tmp_path / "library.blend")
    bpy.data.libraries.write(library, {source}, fake_user=True)
    bpy.data.objects.remove(source)
    with bpy.data.libraries.load(library, link=True) as (data_from, data_to):
        data_to.objects = ["Rock"]
    rock = data_to.objects[0]
    bpy.context.scene.collection.objects.link(rock)
    bpy.context.view_layer.objects.active = rock
    rock.select_set(True)
    n = len(bpy.data.meshes)
    for op, kw in ((bpy.ops.tessera.loop_subdivide, {"levels": 1, "output": "REPLACE"}),
                   (bpy.ops.tessera.bake_lighting_hce, {"depth": 1})):
        with pytest.raises(RuntimeError, match="'Rock' is linked from .*library.blend"):
            op(**kw)
    assert len(bpy.data.meshes) == n and rock.data.library is not None
    assert bpy.ops.tessera.loop_subdivide(levels=1, output="NEW_OBJECT") == {"FINISHED"}  # a local copy is fine


def test_the_ui_path_of_the_impostor_bake_makes_the_card_of_the_script_path(clean_scene, bpy_module, addon_module):
    bpy = bpy_module
    for image in [i for i in bpy.data.images if i.name.startswith("Cube impostor")]:  # an earlier test's cards
        bpy.data.images.remove(image)
    box = _box(bpy)
    op = UiOperator(bpy, "tessera.impostor_bake", grid=2, tile=16, samples=2, dilation=2)
    op._begin_all(bpy.context)
    assert op.drive(bpy.context) == {"FINISHED"}
    card = bpy.context.active_object
    assert card.name == "Cube impostor" and any("2x2 views of 16px" in text for _, text in op.reports)
    ui_colour = np.array(bpy.data.images["Cube impostor colour"].pixels[:])
    for image in [i for i in bpy.data.images if i.name.startswith("Cube impostor")]:
        bpy.data.images.remove(image)
    bpy.data.objects.remove(card)
    box.select_set(True)
    bpy.context.view_layer.objects.active = box
    assert bpy.ops.tessera.impostor_bake(grid=2, tile=16, samples=2, dilation=2) == {"FINISHED"}  # the kept views
    assert np.array_equal(np.array(bpy.data.images["Cube impostor colour"].pixels[:]), ui_colour)
    assert not addon_module("addon.render_jobs").open_folders()


def test_the_ui_path_bakes_every_selected_object_in_turn_and_esc_undoes_all(clean_scene, bpy_module, addon_module):
    """In the UI the bake renders the selected objects one after another, the status bar saying which; Esc during the
    second removes the first one's card too (one transaction), and no job folder is left."""
    bpy = bpy_module
    bpy.ops.mesh.primitive_cube_add(size=1.0)
    cube = bpy.context.active_object
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(2, 0, 0), segments=8, ring_count=4)
    sphere = bpy.context.active_object
    cube.select_set(True)
    bpy.context.view_layer.objects.active = cube
    op = UiOperator(bpy, "tessera.impostor_bake", grid=2, tile=16, samples=1)
    assert op._begin_all(bpy.context) == {"FINISHED"}
    assert [o.name for o in op._targets] == ["Cube", "Sphere"]
    assert "(1 of 2 objects, Cube)" in op._status_text(op._job.job)
    assert op.drive(bpy.context) == {"FINISHED"}
    cards = sorted(o.name for o in bpy.data.objects if o.name.endswith(" impostor"))
    assert cards == ["Cube impostor", "Sphere impostor"]
    assert {o.name for o in bpy.context.selected_objects} >= set(cards)
    for name in cards:
        bpy.data.objects.remove(bpy.data.objects[name])
    n_images, n_objects = len(bpy.data.images), len(bpy.data.objects)
    for ob in (cube, sphere):
        ob.select_set(True)
    bpy.context.view_layer.objects.active = cube
    op = UiOperator(bpy, "tessera.impostor_bake", grid=2, tile=16, samples=64)  # the second render takes a while
    assert op._begin_all(bpy.context) == {"FINISHED"}
    assert op.drive(bpy.context, until=lambda: op._target == 1) is None  # the first card made, the second rendering
    assert len(bpy.data.objects) == n_objects + 1
    assert op.drive(bpy.context, escape_after=0) == {"CANCELLED"}
    assert (len(bpy.data.images), len(bpy.data.objects)) == (n_images, n_objects)
    assert not addon_module("addon.render_jobs").open_folders()


def _graph(mat):
    nodes = sorted((n.bl_idname, n.label, getattr(n, "operation", ""), getattr(n, "interpolation", ""))
                   for n in mat.node_tree.nodes)
    links = sorted((lk.from_node.bl_idname, lk.from_socket.identifier, lk.to_node.bl_idname, lk.to_socket.identifier)
                   for lk in mat.node_tree.links)
    values = sorted((n.bl_idname, s.identifier, round(float(s.default_value), 6)) for n in mat.node_tree.nodes
                    for s in n.inputs if not s.is_linked and s.type == "VALUE")
    return nodes, links, values


def test_a_later_card_copies_the_material_of_its_kind_with_its_own_atlas(clean_scene, bpy_module, addon_module):
    """Building a card's ~120 nodes takes tens of ms; a card of the same kind copies a local one instead: the same
    graph, its own images."""
    bpy = bpy_module
    bake = addon_module("addon.impostors.bake")
    cards = []
    for k, blend in enumerate((True, True, False)):
        bpy.ops.mesh.primitive_cube_add(location=(3 * k, 0, 0))
        assert bpy.ops.tessera.impostor_bake(grid=2, tile=8, samples=1, blend=blend) == {"FINISHED"}
        cards.append(bpy.context.active_object)
    first, second, unblended = (c.active_material for c in cards)
    assert first[bake.MATERIAL_KIND] == second[bake.MATERIAL_KIND] != unblended[bake.MATERIAL_KIND]
    assert _graph(first) == _graph(second) and _graph(first) != _graph(unblended)
    seen = set()
    for card, mat in zip(cards, (first, second, unblended), strict=True):
        used = {n.image.name.rsplit(".", 1)[0] if n.image.name[-4:-3] == "." else n.image.name: n.image
                for n in mat.node_tree.nodes if n.type == "TEX_IMAGE"}
        assert sorted(used) == sorted(f"{card.name} {k}" for k in ("colour", "normal", "depth")), used
        assert not seen & set(used.values())  # its own images, none of another card's
        seen |= set(used.values())
    # the material built fresh (no card of its kind in the file) is the one copied
    copied = [n for n in _graph(second)[0] if "for export" not in n[1]]
    for card in cards:
        bpy.data.materials.remove(card.active_material)
    fresh = bake.card_material("fresh", bpy.data.images[f"{cards[1].name} colour"], 2, False, True)
    assert _graph(fresh)[0] == copied


def test_progress_moves_within_a_view(clean_scene, bpy_module, addon_module, tmp_path):
    """The status bar's share comes from the worker's step lines and, within a step, from its sample lines (a real
    worker's log holds them)."""
    bpy = bpy_module
    bake = addon_module("addon.impostors.bake")
    jobs = addon_module("addon.render_jobs")
    aj = bake.start_atlas(_box(bpy), grid=1, tile=32, samples=8)
    aj.job.process.wait(timeout=300)
    real = aj.job._log_bytes()
    aj.job.wait(lambda line: None, "Baking impostor views", timeout=300)
    bake.read_atlas(aj)  # reading the views removes the job's folder
    assert aj.job.folder not in jobs.open_folders()
    assert b"TESSERA_PROGRESS 1/1" in real, real[-600:]
    if addon_module("addon.compat").RENDER_STATS_IN_WORKERS:
        assert re.search(rb"TESSERA_SAMPLES [1-7]/8", real), real[-600:]
    log = (tmp_path / "log")
    log.write_bytes(b"TESSERA_DEVICE CPU\nTESSERA_SAMPLES 2/8\nTESSERA_SAMPLES 4/8\n")
    job = jobs.RenderJob(None, str(tmp_path / "folder"), 2, str(log))
    try:
        assert job.fraction() == 0.5 and job.progress() == 0
        with open(log, "ab") as f:
            f.write(b"TESSERA_PROGRESS 1/2\nTESSERA_SAMPLES 6/8\nTESSERA_SAM")  # half a line: not read yet
        assert job.fraction() == 1.75 and job.progress() == 1
        with open(log, "ab") as f:
            f.write(b"PLES 8/8\nTESSERA_PROGRESS 2/2\n")
        assert job.fraction() == 2.0 and job.progress() == 2
    finally:
        jobs._open_jobs.pop(job.folder, None)


def _leashed(render_jobs, tmp_path, body):
    """A worker running the Python ``body`` on a leash, in a job folder: (process, folder)."""
    folder = render_jobs.job_folder("bake")
    script = tmp_path / "worker.py"
    script.write_text(body)
    job = os.path.join(folder, "job.json")
    with open(job, "w") as f:
        f.write("{}")
    return render_jobs.start_worker(script, job, os.path.join(folder, "worker.log")), folder


def test_a_worker_that_dies_is_told_by_its_reason_not_its_start_up_lines(addon_module, tmp_path):
    render_jobs = addon_module("addon.render_jobs")
    process, folder = _leashed(render_jobs, tmp_path, "import os, signal, sys\n"
                               "print('Blender 5.2 (hash 1234) started', flush=True)\n"
                               "print('Read prefs: userpref.blend', flush=True)\n"
                               "os.kill(os.getpid(), signal.SIGSEGV)\n")
    assert process.wait(timeout=60) == -11  # the leash ends as its worker did
    job = render_jobs.RenderJob(process, folder, 1, os.path.join(folder, "worker.log"))
    with pytest.raises(Exception) as err:
        job.check("Baking the lighting")
    job.close()
    assert str(err.value) == "Baking the lighting failed: the render process ended early (it crashed (SIGSEGV))"
    said = render_jobs.failure("Rendering", -9, b"Blender 5.2 started\nFra:1 Mem:12M | Error: CUDA device lost\n"
                                                b"Blender quit\n")
    assert said == ("Rendering failed: the render process ended early (it was killed (SIGKILL; most often the system "
                    "ran out of memory)): Fra:1 Mem:12M | Error: CUDA device lost")
    assert render_jobs.failure("Rendering", 3, b"Read blend\n").endswith("(it exited with code 3)")


def test_closing_a_workers_leash_ends_it_and_removes_its_folder(addon_module, tmp_path):
    render_jobs = addon_module("addon.render_jobs")
    process, folder = _leashed(render_jobs, tmp_path, "import time\ntime.sleep(600)\n")
    time.sleep(0.5)
    worker = [pid for pid in processes_naming(str(tmp_path / "worker.py")) if pid != process.pid]
    assert worker, "the worker did not start"
    assert render_jobs.stop_process(process, timeout=10)
    assert not os.path.exists(folder)  # removed by the leash
    render_jobs.remove_folder(folder)
    for pid in worker:
        assert not os.path.exists(f"/proc/{pid}") or "Z" in open(f"/proc/{pid}/stat").read().split()[2]


def test_an_object_drawn_by_its_live_board_still_counts_its_faces(clean_scene, bpy_module, addon_module):
    """Under the preview modifier (what the viewport draws while the board stands for the object: zero-size
    instances) the object still renders its geometry: it is not refused as having no faces."""
    bpy = bpy_module
    worker, viewport = addon_module("addon.impostors.worker"), addon_module("addon.viewport")
    ob = _box(bpy)
    mod = ob.modifiers.new(viewport.SOURCE_MODIFIER, "NODES")
    mod.node_group = viewport._source_group()
    bpy.context.view_layer.update()
    assert len(ob.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh().polygons) == 0  # what is drawn
    worker.check_renderable(ob)  # what renders: the box

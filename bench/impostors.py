"""Nailboards ([Clua et al., §6] and its lifetime claim), in one run on this machine (llvmpipe):

- ``lifetime``: a sphere's board rendered by the Cycles worker for an eye O1; the camera then strafes sideways (and,
  separately, dollies in). Each frame the board is drawn relief-mapped (pre-warped for the current eye) and as a
  plain sprite (the image as made, pre-warped for O1), and compared with the sphere mesh drawn from the same eye:
  the measured error is the area where they differ over the true outline's length (the mean displacement of the
  outline, in pixels). Lifetime: frames until that error passes 1 px. Reported for both, and their ratio: the
  paper's claim that relief-mapped boards stay valid longer.
- ``r1``: the longest and the mean draw of the board (pre-warp + upload + draw, what the viewport callback does per
  frame) while the worker renders another board, against the same with the worker idle ([Clua et al.]: 171 vs 171 fps).
- ``r1_request_pause``: the main thread's pause to ask for a board in a scene that also holds a 4M-triangle mesh,
  against saving a copy of the file (what the request did before it wrote only the object, its lights and world).
- ``resampled_board_frame``: the per-frame CPU share (pre-warp + hole filling) of a 1024² sphere board against the
  same board resampled to 256² (what the manager draws once the view needs a quarter of the texels).
- ``k``: for tolerance K = 1, 1.5, 2, 4 the frame at which the validity tests (`kernels.impostors.validity`) ask for
  a new board on the strafe, and the error measured there (R5).
- ``r3_*``: the live manager (`addon.impostors.live.NailboardManager`) on a 10 s camera path at 60 frames/s (a
  sweep back and forth around the object while the distance breathes), with a renderer that takes a fixed number of
  frames per board, and the techniques switched on in turn: a new board whenever the eye moved (the baseline), the
  validity metric (K = 1), the cache of recent boards (reuse), velocity prediction. Reported: renders asked for per
  second, boards swapped in per second (the effective update rate), cache hits, and the share of frames drawn from a
  board that is valid for that frame's eye (R3).
Run: .venv/bin/python bench/impostors.py (``--r3``: the R3 rows only)
"""

import atexit
import importlib
import json
import shutil
import sys
import time

import numpy as np
from _setup import enable_extension, seconds

SIZE = 200
FRAMES = 40


R3_FPS, R3_SECONDS, R3_LATENCY = 60, 10.0, 6  # frames a second, path length, frames a render takes


class _TimedJob:
    """A render that finishes after a fixed number of the manager's frames (what the worker's job offers)."""

    clock = [0]

    def __init__(self, setup, latency):
        self.setup, self.ready = setup, self.clock[0] + latency

    def done(self):
        return self.clock[0] >= self.ready

    def result(self):
        return "images"

    def cancel(self):
        self.ready = float("inf")


def r3_cases(mod, ob, fov):
    """R3 on the live manager with a fixed-latency renderer (no Cycles: the counts depend on the path and the
    tests, not on the render)."""
    live, va, board = mod("addon.impostors.live"), mod("kernels.impostors.validity"), mod("kernels.impostors.board")
    lo, hi = live.world_box(ob)

    def request(ob, eye, res_screen, fov):
        return _TimedJob(board.board_setup(lo, hi, eye, res_screen, fov), R3_LATENCY)

    n = int(R3_FPS * R3_SECONDS)
    t = np.arange(n) / R3_FPS
    angle = 0.35 * np.sin(2 * np.pi * t / 6.0)  # back and forth over 40 degrees, period 6 s (at most 21 deg/s)
    radius = 6.0 + 1.0 * np.sin(2 * np.pi * t / 9.0)
    eyes = np.stack([radius * np.sin(angle), -radius * np.cos(angle), 0.25 * radius], axis=1)
    configs = (("every_move", dict(k=1e-9, cache_size=0, lead=0)), ("metric", dict(k=1.0, cache_size=0, lead=0)),
               ("metric_reuse", dict(k=1.0, cache_size=8, lead=0)),
               ("metric_reuse_prediction", dict(k=1.0, cache_size=8, lead=R3_LATENCY)))
    for name, cfg in configs:
        manager = live.NailboardManager(request, relief_factor=0.25, **cfg)
        _TimedJob.clock[0] = 0
        swaps, valid, empty, last = 0, 0, 0, None
        for frame, eye in enumerate(eyes):
            _TimedJob.clock[0] = frame
            state = manager.update(ob, eye, SIZE, fov)
            if state.board is not None and state.board is not last:
                swaps += 1
            last = state.board
            if state.board is None:
                empty += 1
            elif not va.check(state.board, eye, fov, SIZE, 1.0, 0.25).regenerate:
                valid += 1
        print(json.dumps({"bench": "impostors", "case": f"r3_{name}", "frames": n, "fps": R3_FPS,
                          "render_latency_frames": R3_LATENCY, "renders_per_second": round(manager.regenerations
                                                                                           / R3_SECONDS, 2),
                          "boards_swapped_in_per_second": round(swaps / R3_SECONDS, 2),
                          "cache_hits": manager.cache_hits, "frames_valid_share": round(valid / n, 3),
                          "frames_without_board": empty}), flush=True)


def main():
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    package = enable_extension()
    mod = lambda name: importlib.import_module(f"{package}.{name}")  # noqa: E731
    mod("addon.gpu_context").ensure_gpu_context()
    pw, va = mod("kernels.impostors.prewarp"), mod("kernels.impostors.validity")
    worker, board_draw = mod("addon.impostors.worker"), mod("gpu_shaders.impostors.draw")
    offscreen, camera = mod("gpu_shaders.offscreen"), mod("kernels.common.camera")
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=1.0)
    ball = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    fov = 0.6
    r3_cases(mod, ball, fov)
    if "--r3" in sys.argv:
        return
    o1 = np.array([0.0, -6.0, 1.5])
    images = worker.request_board(ball, o1, res_screen=SIZE, fov=fov, samples=1).result(timeout=600)
    frame = images.setup.frame
    red = np.zeros(images.colours.shape, np.float32)
    red[..., 0], red[..., 3] = 1.0, 1.0
    me = ball.data
    me.calc_loop_triangles()
    pos = np.array([v.co for v in me.vertices], np.float32)
    tris = np.array([t.vertices[:] for t in me.loop_triangles], np.int32)

    def cam(eye):
        c = camera.Camera(camera.look_at_view(eye, (0, 0, 0)), camera.perspective(fov, 1.0, 0.5, 50.0), SIZE, SIZE)
        return c.projection @ c.view

    def board_mask(eye, warp_eye):
        splat = pw.fill_holes(pw.forward_splat(images.displacement, frame, warp_eye, images.present), 4)
        data = board_draw.BoardDrawData(frame, red, images.displacement, splat)
        return offscreen.render(lambda: data.draw(cam(eye)), size=(SIZE, SIZE))[..., 0] > 127

    def truth(eye):
        return offscreen.render_triangles(pos, tris, cam(eye), size=(SIZE, SIZE), color=(1, 0, 0, 1),
                                          lit=False)[..., 0] > 127

    def error(mask, want):
        pad = np.pad(want, 1, mode="edge")
        outline = (pad[1:-1, :-2] != want) | (pad[1:-1, 2:] != want) | (pad[:-2, 1:-1] != want) | (
            pad[2:, 1:-1] != want)
        return float((mask != want).sum() / max(outline.sum() / 2, 1))

    paths = {"strafe": [o1 + np.array([0.05 * k, 0, 0]) for k in range(FRAMES)],
             "dolly": [o1 * (1 - 0.012 * k) for k in range(FRAMES)]}
    errors = {}
    for name, eyes in paths.items():
        rel, plain = [], []
        for eye in eyes:
            want = truth(eye)
            rel.append(error(board_mask(eye, eye), want))
            plain.append(error(board_mask(eye, o1), want))
        errors[name] = (rel, plain)

        def life(errs):
            return next((k for k, e in enumerate(errs) if e > 1.0), len(errs))

        lr, lp = life(rel), life(plain)
        print(json.dumps({"bench": "impostors", "case": f"lifetime_{name}",
                          "board_texels": int(images.setup.resolution), "relief_frames": lr, "plain_frames": lp,
                          "ratio": round(lr / max(lp, 1), 2),
                          "relief_error_px": [round(e, 2) for e in rel[::8]],
                          "plain_error_px": [round(e, 2) for e in plain[::8]],
                          "threshold_px": 1.0}), flush=True)

    board = va.Board(o1, np.array([-1.0, -1, -1]), np.array([1.0, 1, 1]), images.setup.resolution)
    for k_tol in (1.0, 1.5, 2.0, 4.0):
        hit = next((i for i, e in enumerate(paths["strafe"]) if va.check(board, e, fov, SIZE, k_tol, 1.0).regenerate),
                   None)
        measured = errors["strafe"][1][hit] if hit is not None else None
        print(json.dumps({"bench": "impostors", "case": f"k_{k_tol:g}", "plain_regenerate_at_frame": hit,
                          "measured_plain_error_px_there": None if measured is None else round(measured, 2)}),
              flush=True)

    def draw_times(busy):
        job = worker.request_board(ball, o1 + np.array([2.0, 0, 0]), SIZE, fov, samples=64) if busy else None
        times = []
        for eye in paths["strafe"][:20]:
            t = time.perf_counter()
            board_mask(eye, eye)
            times.append(time.perf_counter() - t)
        if job is not None:
            still = not job.done()
            job.cancel()
        else:
            still = None
        return times, still

    idle, _ = draw_times(False)
    busy, running = draw_times(True)
    print(json.dumps(request_pause_case(bpy, worker, ball, o1, fov)), flush=True)
    print(json.dumps(resample_case(mod)), flush=True)
    print(json.dumps({"bench": "impostors", "case": "r1_draw_with_worker", "worker_running_throughout": running,
                      "busy_max_ms": round(1e3 * max(busy), 1), "busy_mean_ms": round(1e3 * np.mean(busy), 1),
                      "idle_max_ms": round(1e3 * max(idle), 1), "idle_mean_ms": round(1e3 * np.mean(idle), 1),
                      "mean_ratio": round(np.mean(busy) / np.mean(idle), 2)}), flush=True)


def resample_case(mod, repeat=5):
    """The per-frame CPU share of a live board (pre-warp + hole filling, `addon.impostors.preview`) for a sphere board
    of 1024² texels, against the same board resampled to 256² (what the manager draws once the view needs a quarter of
    the texels: zoomed out); and the one-off cost of that resampling."""
    pw, board, resample = (mod(f"kernels.impostors.{m}") for m in ("prewarp", "board", "resample"))
    n = 1024
    setup = board.board_setup(np.full(3, -1.0), np.full(3, 1.0), np.array([0.0, -9.0, 0.0]), 8 * n, 0.5,
                              max_resolution=n)
    c = (np.arange(n) + 0.5) / n * setup.size - setup.size / 2
    x, y = np.meshgrid(c, c)
    present = x * x + y * y < 1.0
    d = np.where(present, setup.size / 2 + np.sqrt(np.maximum(1 - x * x - y * y, 0.0)), 0.0)
    normals = np.stack([x, y, np.sqrt(np.maximum(1 - x * x - y * y, 0.0))], -1).astype(np.float32)
    colours = np.ones((n, n, 4), np.float32)
    eye = np.array([0.8, -9.0, 0.5])

    def frame_cost(s, disp, mask):
        return seconds(lambda: pw.fill_holes(pw.forward_splat(disp, s.frame, eye, mask), 4), repeat)

    t = time.perf_counter()
    small = resample.resample_board(setup, colours, d, normals, present, n // 4)
    once = time.perf_counter() - t
    fine, coarse = frame_cost(setup, d, present), frame_cost(small[0], small[2], small[4])
    return {"bench": "impostors", "case": "resampled_board_frame", "texels": f"{n // 4}²",
            "seconds": round(coarse, 4), "baseline": f"the board drawn at its {n}² texels", "baseline_seconds":
            round(fine, 4), "ratio": round(fine / coarse, 1), "resample_once_seconds": round(once, 3)}


def request_pause_case(bpy, worker, ball, eye, fov, repeat=3):
    """The main thread's pause to ask for a board (`worker.request_board`: write the job, start the process) in a scene
    that also holds a 4-million-triangle mesh the board does not need, against saving a copy of the file (what a
    worker that opens the whole scene needs, and what the request did before): best of ``repeat``."""
    import os
    import tempfile

    bpy.ops.mesh.primitive_grid_add(x_subdivisions=1414, y_subdivisions=1414, location=(20, 0, 0))
    heavy = bpy.context.active_object
    folder = tempfile.mkdtemp(prefix="tessera-bench-")
    atexit.register(shutil.rmtree, folder, ignore_errors=True)
    ours, saves = [], []
    for _ in range(repeat):
        t = time.perf_counter()
        job = worker.request_board(ball, eye, SIZE, fov, samples=1)
        ours.append(time.perf_counter() - t)
        job.cancel()
        t = time.perf_counter()
        bpy.ops.wm.save_as_mainfile(filepath=os.path.join(folder, "copy.blend"), copy=True)
        saves.append(time.perf_counter() - t)
    mesh = heavy.data
    bpy.data.objects.remove(heavy)
    bpy.data.meshes.remove(mesh)
    return {"bench": "impostors", "case": "r1_request_pause", "scene_triangles": 2 * 1413 * 1413 + 64 * 30 * 2,
            "seconds": round(min(ours), 4), "baseline": "save a copy of the file", "baseline_seconds":
            round(min(saves), 4), "ratio": round(min(saves) / min(ours), 1)}


if __name__ == "__main__":
    main()

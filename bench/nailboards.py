"""Nailboards (seed 003 §B.7, digest §B.11 R1 and the lifetime claim), in one run on this machine (llvmpipe):

- ``lifetime``: a sphere's board rendered by the Cycles worker for an eye O1; the camera then strafes sideways (and,
  separately, dollies in). Each frame the board is drawn relief-mapped (pre-warped for the current eye) and as a
  plain sprite (the image as made, pre-warped for O1), and compared with the sphere mesh drawn from the same eye:
  the measured error is the area where they differ over the true outline's length (the mean displacement of the
  outline, in pixels). Lifetime: frames until that error passes 1 px. Reported for both, and their ratio: the
  seed's claim that relief-mapped boards stay valid longer.
- ``r1``: the longest and the mean draw of the board (pre-warp + upload + draw, what the viewport callback does per
  frame) while the worker renders another board, against the same with the worker idle (the seed: 171 vs 171 fps).
- ``k``: for tolerance K = 1, 1.5, 2, 4 the frame at which the validity tests (`kernels.impostors.validity`) ask for
  a new board on the strafe, and the error measured there (R5).
Run: .venv/bin/python bench/nailboards.py
"""

import importlib
import json
import time

import numpy as np
from _setup import enable_extension

SIZE = 200
FRAMES = 40


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
        print(json.dumps({"bench": "nailboards", "case": f"lifetime_{name}",
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
        print(json.dumps({"bench": "nailboards", "case": f"k_{k_tol:g}", "plain_regenerate_at_frame": hit,
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
    print(json.dumps({"bench": "nailboards", "case": "r1_draw_with_worker", "worker_running_throughout": running,
                      "busy_max_ms": round(1e3 * max(busy), 1), "busy_mean_ms": round(1e3 * np.mean(busy), 1),
                      "idle_max_ms": round(1e3 * max(idle), 1), "idle_mean_ms": round(1e3 * np.mean(idle), 1),
                      "mean_ratio": round(np.mean(busy) / np.mean(idle), 2)}), flush=True)


if __name__ == "__main__":
    main()

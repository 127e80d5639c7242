"""Background renders in a session: how long the main thread (Blender's UI) is held while an impostor bake, two
nailboards and a lighting bake render at once, against how long it was held when each waited for its render (the
baseline: the render's whole time, what a bake froze Blender for before they became jobs).

The session is what the operators' timers do, in one run: every job is started, then polled every 20 ms as the
timers poll them (progress, device, whether done); once a worker is done its files are read on a worker thread (a
board's images; the impostor's views, read and dilated; the lighting's colours, read and encoded), and the main thread
only makes what Blender must make itself, a piece per timer tick (the impostor's three packed images, then its card;
the lighting's stored bytes). A card copies the material of an earlier card of its kind (`step` rows: the first card
builds it). Every main-thread step is timed; rows give the longest. The impostor is the bake's default, 8 x 8 views of
128 px. The scene holds a
Suzanne at subdivision level 3 (63k triangles), a floor, two lights; ``heavy_scene`` adds a 1M-triangle mesh, which
the lighting bake writes with the scene (it needs every object for the bounced light) while the impostor and board
jobs write only their object, its lights and world.
Run: .venv/bin/python bench/render_jobs.py
"""

import importlib
import json
import time
from functools import partial

import numpy as np
from _setup import enable_extension

GRID, TILE = 8, 128  # the impostor bake's defaults: a 1024² atlas


def _scene(bpy, heavy):
    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.ops.mesh.primitive_monkey_add()
    ob = bpy.context.active_object
    ob.modifiers.new("s", "SUBSURF").levels = 3
    bpy.ops.object.modifier_apply(modifier="s")
    bpy.ops.mesh.primitive_plane_add(size=8, location=(0, 0, -1.2))
    bpy.ops.object.light_add(type="AREA", location=(0, 0, 3))
    bpy.ops.object.light_add(type="SUN", location=(2, -2, 4))
    if heavy:
        bpy.ops.mesh.primitive_grid_add(x_subdivisions=710, y_subdivisions=710, size=30, location=(0, 0, -2))
    bpy.context.view_layer.objects.active = ob
    return ob


def _timed(steps, job, fn, what="poll"):
    """Call ``fn`` on the main thread, recording (seconds, ``what``) under ``job``: its result (the seconds for
    "copy")."""
    t = time.perf_counter()
    result = fn()
    steps.setdefault(job, []).append((time.perf_counter() - t, what))
    return result if job != "copy" else steps[job][-1][0]


def session(bpy, mod, heavy):
    bake = importlib.import_module(f"{mod}.addon.impostors.bake")
    worker = importlib.import_module(f"{mod}.addon.impostors.worker")
    light = importlib.import_module(f"{mod}.addon.subdivision.bake")
    loop = importlib.import_module(f"{mod}.kernels.subdivision.loop")
    bridge = importlib.import_module(f"{mod}.addon.bridge")
    workers = importlib.import_module(f"{mod}.kernels.common.workers")
    impostor_op = importlib.import_module(f"{mod}.operators.impostors")
    lighting_op = importlib.import_module(f"{mod}.operators.subdivision")
    ob = _scene(bpy, heavy)
    arrays, _ = bridge.read_mesh(ob.data)
    coarse = arrays.triangles[:4000]  # the lighting bake of 4,000 of its triangles at depth 2
    sub = loop.loop_subdivide(arrays.positions, coarse, 2)
    what = ("Suzanne", type(arrays)(positions=arrays.positions, triangles=coarse), sub)
    steps, started = {}, time.perf_counter()
    atlas = _timed(steps, "impostor", lambda: bake.start_atlas(ob, grid=GRID, tile=TILE, samples=16), "start")
    boards = [_timed(steps, f"board {k}", lambda k=k: worker.request_board(ob, np.array([6.0, -4.0 + 3 * k, 2.0]),
                                                                            512, 0.7, samples=16), "start")
              for k in range(2)]
    lit = _timed(steps, "lighting", lambda: light.start_bake(bpy.context, ob, sub.positions, sub.triangles,
                                                             np.zeros(len(sub.triangles), np.int32), 16, True, 0),
                 "start")
    ended, pending, reading = {}, {"impostor", "board 0", "board 1", "lighting"}, {}
    while pending:
        time.sleep(0.02)
        if "impostor" in pending:  # what the operator's timer does (operators/impostors.py, modal)
            running = _timed(steps, "impostor", lambda: (atlas.job.progress(), atlas.job.device(),
                                                        atlas.job.running())[-1])
            if not running and "impostor" not in reading:
                reading["impostor"] = workers.submit(impostor_op._read_dilated, atlas, 4)
            elif not running and reading["impostor"].done():  # one image per tick, then the card
                _, ready = reading["impostor"].result()
                images = {}
                for key, pixels in bake.atlas_pixels(ready).items():  # its pixels, then its packing
                    image_steps = bake.packed_float_image_steps(f"S {key}", pixels)
                    _timed(steps, "impostor", partial(next, image_steps), f"{key} image")
                    time.sleep(0.02)
                    images[key] = _timed(steps, "impostor", partial(bake.run_to_end, image_steps), f"{key} image")
                    time.sleep(0.02)
                card_steps = bake.make_card_steps("Suzanne impostor", ready, images, None)
                parts, done = [], False
                while not done:  # the card, a part of its material per tick
                    t = time.perf_counter()
                    try:
                        next(card_steps)
                    except StopIteration:
                        done = True
                    parts.append(time.perf_counter() - t)
                    steps["impostor"].append((parts[-1], "card"))
                    time.sleep(0.02)
                card_ms = sum(parts) * 1e3
                # a second card of the kind: its material is copied, not built
                copy_ms = _timed({}, "copy", partial(bake.make_card, "Suzanne impostor 2", ready, images, None))
                pending.discard("impostor")
                ended["impostor"] = time.perf_counter() - started
        for k, job in enumerate(boards):
            name = f"board {k}"
            if name in pending:
                _timed(steps, name, job.poll)
                if job.done():
                    _timed(steps, name, job.result, "result")
                    pending.discard(name)
                    ended[name] = time.perf_counter() - started
        if "lighting" in pending:  # operators/subdivision.py, modal
            running = _timed(steps, "lighting", lambda: (lit.job.progress(), lit.job.device(), lit.job.running())[-1])
            if not running and "lighting" not in reading:
                reading["lighting"] = workers.submit(
                    lambda: lighting_op._encode(light.read_bake(lit), what, 2, 2, 1.0 / 255))
            elif not running and reading["lighting"].done():
                _timed(steps, "lighting", lambda: reading["lighting"].result(), "result")
                pending.discard("lighting")
                ended["lighting"] = time.perf_counter() - started
    print(json.dumps({"case": "heavy_scene" if heavy else "session", "step": "the impostor's card",
                      "first_card_ms (material built)": round(card_ms, 1), "first_card_ticks": len(parts),
                      "longest_tick_ms": round(max(parts) * 1e3, 1),
                      "later_card_ms (material copied)": round(copy_ms * 1e3, 1),
                      "ratio": round(card_ms / (copy_ms * 1e3), 1)}), flush=True)
    for job, times in steps.items():
        longest, what = max(times)
        print(json.dumps({"case": "heavy_scene" if heavy else "session", "job": job,
                          "start_ms": round(times[0][0] * 1e3, 1), "longest_step_ms": round(longest * 1e3, 1),
                          "longest_step": what, "steps": len(times),
                          "render_s (baseline: the UI held)": round(ended[job], 2),
                          "longest_step_vs_baseline": round(longest / ended[job], 4)}), flush=True)


def main():
    import bpy

    mod = enable_extension()

    for heavy in (False, True):
        session(bpy, mod, heavy)


if __name__ == "__main__":
    main()

"""OpenCL map kernels (``map_dabs.cl``, custom kernels) against the numpy reference (tier: opencl)."""

import numpy as np
import pytest
from tessera.kernels.common.errors import TesseraError
from tessera.kernels.common.tolerances import FLOAT32_PATH_ATOL
from tessera.tools.generators import random_dabs

pytestmark = pytest.mark.opencl




@pytest.mark.parametrize("channels", [1, 3, 4])
def test_map_kernels_equal_the_numpy_reference(opencl, channels):
    from tessera.kernels.displacement.map_edit import apply_dab

    rng = np.random.default_rng(channels)
    base = rng.normal(size=(64, 72, channels)).astype(np.float32)
    for kind, params in random_dabs(rng, channels):
        a, b = base.copy(), base.copy()
        ra = apply_dab(a, kind, backend="opencl", **params)
        rb = apply_dab(b, kind, backend="numpy", **params)
        assert ra == rb, kind
        # the same float32 operations, contraction off, division and sqrt correctly rounded (the runtime's build
        # option): the device gives the reference's bytes (PoCL and NVIDIA's driver both do)
        assert a.tobytes() == b.tobytes(), (kind, np.abs(a - b).max())
        if ra is not None:
            x0, y0, x1, y1 = ra
            outside = np.ones(base.shape[:2], bool)
            outside[y0:y1, x0:x1] = False
            assert np.array_equal(a[outside], base[outside]), kind  # outside the footprint: untouched


def test_device_resident_map_equals_the_numpy_reference(opencl):
    """A map kept on the device across a whole stroke of mixed dabs ends where the reference ends."""
    from tessera.kernels.displacement.map_buffer import MapBuffer
    from tessera.kernels.displacement.map_edit import apply_dab, smooth_map

    rng = np.random.default_rng(11)
    for channels in (1, 4):
        a = rng.normal(size=(80, 96, channels)).astype(np.float32)
        b = a.copy()
        device = MapBuffer(opencl, a)
        for kind, params in random_dabs(rng, channels):
            assert apply_dab(a, kind, device=device, backend="opencl", **params) == apply_dab(b, kind, backend="numpy",
                                                                                               **params)
        smooth_map(a, 0.7, device=device)
        smooth_map(b, 0.7, backend="numpy")
        assert np.allclose(a, b, rtol=0, atol=1e-5), np.abs(a - b).max()
        b[3:9, 5:40] = 2.5  # a host-side edit (undo, a file) pushed to the device is seen by the next dab
        a[...] = b
        device.push()
        apply_dab(a, "SMOOTH", device=device, backend="opencl", pos=(20, 6), radius=9, strength=1.0)
        apply_dab(b, "SMOOTH", backend="numpy", pos=(20, 6), radius=9, strength=1.0)
        assert np.allclose(a, b, rtol=0, atol=FLOAT32_PATH_ATOL)


def test_auto_strokes_run_where_they_were_measured_faster(opencl, monkeypatch):
    """With a device and ``auto``, each stroke runs on the side its kind and footprint were measured faster on per
    dab (`MapBuffer.stroke_times`; here the times are made up: DRAW is faster on the device, SMOOTH on the host).
    The map ends as the reference's bytes, the device copy equals the host, the slower side runs only to try it and
    to recheck it, and a device stroke of DRAW dabs is one launch."""
    from tessera.kernels.displacement import dab_batch, map_edit
    from tessera.kernels.displacement.dab_timing import DEVICE, HOST
    from tessera.kernels.displacement.map_buffer import MapBuffer
    from tessera.kernels.displacement.map_strokes import Brush, run_stroke, stroke_dabs

    launches, batches = [], []
    run, launch = map_edit._run_opencl, dab_batch.launch
    monkeypatch.setattr(map_edit, "_run_opencl", lambda *args, **kw: (launches.append(args[3]), run(*args, **kw))[1])
    monkeypatch.setattr(dab_batch, "launch", lambda *args: (batches.append(len(args[1])), launch(*args))[1])
    rng = np.random.default_rng(12)
    a = rng.normal(size=(70, 90, 1)).astype(np.float32)
    b = a.copy()
    device = MapBuffer(opencl, a)
    made_up = {("DRAW", DEVICE): 1e-4, ("DRAW", HOST): 2e-4, ("SMOOTH", DEVICE): 2e-4, ("SMOOTH", HOST): 1e-4}
    sides, dabs = [], {}
    record = device.stroke_times.record
    monkeypatch.setattr(device.stroke_times, "record", lambda kind, texels, side, seconds: (
        sides.append((kind, side)), record(kind, texels, side, made_up[kind, side])))
    for kind in ("DRAW", "SMOOTH") * 24:
        brush = Brush(kind=kind, radius=9.0, strength=0.3, spacing=0.3)
        path = np.column_stack([rng.uniform(20, 50, 2), rng.uniform(20, 50, 2), rng.uniform(0.3, 1, 2)])
        run_stroke(a, brush, path, backend="auto", device=device)
        run_stroke(b, brush, path, backend="numpy")
        side = sides[-1][1]
        dabs[kind, side] = dabs.get((kind, side), 0) + len(stroke_dabs(path, brush.spacing * brush.radius))
    assert a.tobytes() == b.tobytes()
    on_device = np.empty_like(a)
    opencl.cl.enqueue_copy(opencl.queue, on_device, device.sync())
    assert on_device.tobytes() == a.tobytes()
    for kind, fast, slow in (("DRAW", DEVICE, HOST), ("SMOOTH", HOST, DEVICE)):
        assert sides.count((kind, fast)) > 3 * sides.count((kind, slow)) > 0, kind  # the slower: trials, rechecks
    assert launches.count("draw") == 0 and len(batches) == sides.count(("DRAW", DEVICE))  # one launch a stroke
    assert sum(batches) == dabs["DRAW", DEVICE]
    assert launches.count("smooth") == dabs["SMOOTH", DEVICE] > 0  # SMOOTH: a launch a dab, read back together


def test_auto_backend_without_a_device_copy_also_runs_where_measured_faster(opencl, monkeypatch):
    """A map without a `MapBuffer` (each device dab uploads its tile): ``auto`` picks the side by the runtime's
    `dab_timing.tile_times`; with made-up times that put DRAW on the host, a stroke launches only its trials and
    rechecks on the device, and the map ends as the reference's bytes."""
    from tessera.kernels.common.opencl_runtime import get_runtime
    from tessera.kernels.displacement import dab_timing, map_edit
    from tessera.kernels.displacement.dab_timing import DEVICE, HOST
    from tessera.kernels.displacement.map_strokes import Brush, run_stroke

    monkeypatch.setattr(dab_timing, "_TILE_TIMES", {})  # nothing learnt by earlier tests
    launches = []
    run = map_edit._run_opencl
    monkeypatch.setattr(map_edit, "_run_opencl", lambda *args, **kw: (launches.append(args[3]), run(*args, **kw))[1])
    runtime = get_runtime()  # what apply_dab uses without a device (the session's `opencl` may have been replaced)
    assert runtime is not None
    times = dab_timing.tile_times(runtime)
    assert dab_timing.tile_times(runtime) is times  # one per runtime
    sides = []
    record = times.record
    monkeypatch.setattr(times, "record", lambda kind, texels, side, seconds: (
        sides.append(side), record(kind, texels, side, {HOST: 1e-4, DEVICE: 3e-4}[side])))
    rng = np.random.default_rng(13)
    a = rng.normal(size=(60, 80, 1)).astype(np.float32)
    b = a.copy()
    brush = Brush(kind="DRAW", radius=6.0, strength=0.3, spacing=0.1)
    path = np.column_stack([rng.uniform(10, 50, 4), rng.uniform(10, 50, 4), rng.uniform(0.5, 1, 4)])
    run_stroke(a, brush, path, backend="auto")
    run_stroke(b, brush, path, backend="numpy")
    assert a.tobytes() == b.tobytes()
    assert sides.count(HOST) > 4 * sides.count(DEVICE) > 0
    assert len(launches) == sides.count(DEVICE)  # the device dabs uploaded their tiles and ran the kernel


def test_morphing_kernel_equals_numpy(opencl):
    from tessera.kernels.displacement.map_edit import morph

    rng = np.random.default_rng(5)
    a, b = (rng.normal(size=(40, 50, 3)).astype(np.float32) for _ in range(2))
    for t in (0.0, 0.3, 1.0, 1.7):
        got, want = morph(a, b, t, backend="opencl"), morph(a, b, t, backend="numpy")
        assert np.allclose(got, want, rtol=0, atol=FLOAT32_PATH_ATOL)


def test_custom_kernel_identity_reproduction_and_compile_errors(opencl):
    from tessera.kernels.displacement.map_edit import apply_custom, apply_dab, compile_custom

    rng = np.random.default_rng(6)
    m = rng.normal(size=(32, 32, 4)).astype(np.float32)
    before = m.copy()
    apply_custom(m, compile_custom(opencl, ""), opencl)
    assert np.array_equal(m, before)  # the empty template copies in to out
    body = "if (sqrt(((float)x - arg1.x) * ((float)x - arg1.x) + ((float)y - arg1.y) * ((float)y - arg1.y)) " \
           "< arg3.x) { image += arg2; }"
    args = ((10, 12, 0, 0), (0.1, 0, 0.25, 0), (4, 0, 0, 0), (0, 0, 0, 0))
    apply_custom(m, compile_custom(opencl, body), opencl, args=args)
    expected = before.copy()
    apply_dab(expected, "TEST", backend="numpy", arg1=args[0], arg2=args[1], arg3=args[2])
    assert np.allclose(m, expected, atol=FLOAT32_PATH_ATOL)  # [Andrade 2012]'s test kernel written as a custom body
    with pytest.raises(TesseraError, match="failed to compile") as err:
        compile_custom(opencl, "image += ;")
    assert "error" in str(err.value).lower()


def test_non_finite_results_never_reach_the_map_or_the_device(opencl):
    """A custom kernel writing NaN over the whole map (the region that once aliased the map) and a dab that
    overflows are refused; the host map and the device copy keep every bit."""
    from tessera.kernels.displacement.map_buffer import MapBuffer
    from tessera.kernels.displacement.map_edit import InvalidInputError, apply_custom, apply_dab, compile_custom

    rng = np.random.default_rng(8)
    m = (rng.uniform(-1, 1, size=(48, 40, 4)) * 3e38).astype(np.float32)
    before = m.copy()
    device = MapBuffer(opencl, m)
    for dev in (None, device):
        with pytest.raises(TesseraError, match="NaN or infinite"):
            apply_custom(m, compile_custom(opencl, "image = (float4)(NAN);"), opencl, device=dev)
        assert m.tobytes() == before.tobytes()
    for dev, backend in ((None, "opencl"), (device, "auto"), (device, "opencl")):
        with pytest.raises(InvalidInputError, match="NaN or infinite"):
            apply_dab(m, "DRAW", backend=backend, device=dev, pos=(20, 20), radius=30, strength=3e38,
                      vector=(3e38, 3e38, 3e38, 3e38), falloff="CONSTANT")
        assert m.tobytes() == before.tobytes()
    on_device = np.empty_like(m)
    opencl.cl.enqueue_copy(opencl.queue, on_device, device.buf)
    assert on_device.tobytes() == before.tobytes()

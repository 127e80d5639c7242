"""Strokes on a device-resident map: dabs read back together, DRAW dabs in one launch (`dab_batch`), against the
numpy reference dab by dab."""

import numpy as np
import pytest
from tessera.kernels.common.errors import InvalidInputError, TesseraError
from tessera.kernels.displacement.dab_batch import bin_size, bins
from tessera.kernels.displacement.map_strokes import Brush, TileUndo, run_stroke


def test_each_bin_lists_the_dabs_that_reach_it_in_order():
    rng = np.random.default_rng(3)
    for _ in range(20):
        n = int(rng.integers(1, 40))
        x0, y0 = rng.integers(0, 50, n), rng.integers(0, 50, n)
        regions = np.column_stack([x0, y0, x0 + rng.integers(1, 60, n), y0 + rng.integers(1, 60, n)]).astype(np.int64)
        box = (int(regions[:, 0].min()), int(regions[:, 1].min()), int(regions[:, 2].max()), int(regions[:, 3].max()))
        size = int(rng.choice([1, 3, 8, 16, 64]))
        start, listed, bins_x = bins(regions, box, size)
        bins_y = -(-(box[3] - box[1]) // size)
        assert bins_x == -(-(box[2] - box[0]) // size) and len(start) == bins_x * bins_y + 1
        for b in range(bins_x * bins_y):
            bx0, by0 = box[0] + (b % bins_x) * size, box[1] + (b // bins_x) * size
            reach = [i for i, (a0, b0, a1, b1) in enumerate(regions)
                     if a0 < bx0 + size and bx0 < a1 and b0 < by0 + size and by0 < b1]
            assert listed[start[b]:start[b + 1]].tolist() == reach


def test_bins_are_a_quarter_of_the_largest_footprint():
    assert bin_size(np.array([[0, 0, 33, 33]])) == 8
    assert bin_size(np.array([[0, 0, 129, 40], [5, 5, 20, 20]])) == 32
    assert bin_size(np.array([[0, 0, 3, 3]])) == 8
    assert bin_size(np.array([[0, 0, 20000, 3]])) == 1024


def _stroke_pairs(rng, channels):
    """Brushes and paths: small and large radii (bins of 8 to 64 texels), pressure on the radius, mirrored, off
    the map's edges."""
    for radius, spacing in ((3.0, 0.2), (11.0, 0.1), (40.0, 0.25), (130.0, 0.05)):
        for mirror in (False, True):
            params = {"falloff": str(rng.choice(["SMOOTH", "SPHERE", "LINEAR", "SHARP", "CONSTANT"])),
                      "vector": tuple(rng.normal(size=4)), "cell": float(rng.uniform(0.7, 9)),
                      "seed": int(rng.integers(0, 2**32))}
            brush = Brush(kind="DRAW", radius=radius, strength=float(rng.uniform(-1, 1)), spacing=spacing,
                          pressure_radius=bool(rng.integers(2)), mirror_x=mirror, params=params)
            path = np.column_stack([rng.uniform(-20, 190, 3), rng.uniform(-20, 170, 3), rng.uniform(0.2, 1, 3)])
            yield brush, path


@pytest.mark.opencl
@pytest.mark.parametrize("channels", [1, 3, 4])
@pytest.mark.parametrize("batch_all", [False, True])
def test_a_device_stroke_gives_the_bytes_of_dab_by_dab(opencl, channels, batch_all, monkeypatch):
    """DRAW, CONTACT, FORCE and NOISE strokes (small dabs in one launch, or with ``batch_all`` every dab: bins of 8
    to 64 texels) and SMOOTH strokes (a launch a dab, read back once) on a device map end as the numpy reference,
    dab by dab, ends; the device copy equals the host; undo restores the exact bytes."""
    from tessera.kernels.displacement import dab_batch
    from tessera.kernels.displacement.map_buffer import MapBuffer

    if batch_all:
        monkeypatch.setattr(dab_batch, "MAX_TEXELS", 10**9)

    rng = np.random.default_rng(channels)
    a = rng.normal(size=(150, 170, channels)).astype(np.float32)
    b = a.copy()
    start = a.copy()
    device = MapBuffer(opencl, a)
    undo = TileUndo(a)
    for brush, path in _stroke_pairs(rng, channels):
        for kind in ("DRAW", "CONTACT", "FORCE", "NOISE", "SMOOTH"):
            brush.kind = kind
            assert run_stroke(a, brush, path, backend="opencl", device=device, undo=undo) == \
                run_stroke(b, brush, path, backend="numpy")
            assert device.deferred is None
            assert a.tobytes() == b.tobytes(), (kind, brush.radius, np.abs(a - b).max())
    on_device = np.empty_like(a)
    opencl.cl.enqueue_copy(opencl.queue, on_device, device.sync())
    assert on_device.tobytes() == a.tobytes()
    undo.close(a)
    undo.undo(a)
    assert a.tobytes() == start.tobytes()


@pytest.mark.opencl
@pytest.mark.parametrize("kind", ["DRAW", "SMOOTH"])
def test_a_deferred_stroke_that_overflows_stops_where_dab_by_dab_stops(opencl, kind):
    """Dabs that each add 1e38 overflow where four overlap: the device stroke raises as the reference does, at the
    same dab, with the dabs before it applied, on the host and on the device alike."""
    from tessera.kernels.displacement.map_buffer import MapBuffer

    a = np.random.default_rng(9).normal(size=(40, 120, 1)).astype(np.float32)
    a[:, 60:] = 3e38  # SMOOTH pulls these toward their neighbours; DRAW adds to them
    brush = Brush(kind="DRAW", radius=6.0, strength=1e38, spacing=0.5, params={"falloff": "CONSTANT"})
    if kind == "SMOOTH":
        brush = Brush(kind="SMOOTH", radius=6.0, strength=1.0, spacing=0.5)
        a[:, 59] = -3e38  # a neighbour the mean overflows with
    b, start = a.copy(), a.copy()
    device = MapBuffer(opencl, a)
    path = [(10, 20, 1.0), (110, 20, 1.0)]
    with pytest.raises(InvalidInputError, match="NaN or infinite") as err_ref:
        run_stroke(b, brush, path, backend="numpy")
    with pytest.raises(InvalidInputError, match="NaN or infinite") as err:
        run_stroke(a, brush, path, backend="opencl", device=device)
    assert str(err.value) == str(err_ref.value)
    assert a.tobytes() == b.tobytes() and not np.array_equal(b[:, :50], start[:, :50])  # the dabs before
    on_device = np.empty_like(a)
    opencl.cl.enqueue_copy(opencl.queue, on_device, device.sync())
    assert on_device.tobytes() == a.tobytes()
    assert device.deferred is None


@pytest.mark.opencl
def test_host_work_waits_for_deferred_dabs(opencl):
    """A host dab after deferred device dabs sees them (they are read back first); copying the host over deferred
    edits is refused rather than losing them."""
    from tessera.kernels.displacement.map_buffer import MapBuffer
    from tessera.kernels.displacement.map_edit import apply_dab, flush_deferred

    rng = np.random.default_rng(5)
    a = rng.normal(size=(50, 60, 1)).astype(np.float32)
    b = a.copy()
    device = MapBuffer(opencl, a)
    for kind in ("DRAW", "SMOOTH"):
        apply_dab(a, kind, backend="opencl", device=device, defer=True, pos=(20, 20), radius=8, strength=0.5)
        apply_dab(b, kind, backend="numpy", pos=(20, 20), radius=8, strength=0.5)
    assert device.deferred is not None and a.tobytes() != b.tobytes()
    with pytest.raises(TesseraError, match="not yet read back"):
        device.push()
    with pytest.raises(TesseraError, match="not yet read back"):
        device.smooth_all(0.5)
    apply_dab(a, "DRAW", backend="numpy", device=device, pos=(25, 22), radius=8, strength=0.5)
    apply_dab(b, "DRAW", backend="numpy", pos=(25, 22), radius=8, strength=0.5)
    assert device.deferred is None and a.tobytes() == b.tobytes()
    apply_dab(a, "DRAW", backend="opencl", device=device, defer=True, pos=(30, 30), radius=5, strength=0.5)
    apply_dab(b, "DRAW", backend="numpy", pos=(30, 30), radius=5, strength=0.5)
    flush_deferred(device)
    assert a.tobytes() == b.tobytes()


@pytest.mark.opencl
@pytest.mark.parametrize("fails", ["batched launch", "read-back"])
def test_a_device_failure_at_the_stroke_end_leaves_host_and_device_equal(opencl, monkeypatch, fails):
    """The batched launch or the read-back fails (as a lost device would) when the stroke ends: the error goes on,
    the host keeps the map as it was before the stroke, the device (SMOOTH dabs already ran there) is put back to
    it, and the next stroke runs normally."""
    from tessera.kernels.displacement import dab_batch
    from tessera.kernels.displacement.map_buffer import MapBuffer

    rng = np.random.default_rng(6)
    a = rng.normal(size=(60, 70, 1)).astype(np.float32)
    b, before = a.copy(), a.copy()
    device = MapBuffer(opencl, a)

    def lost(*args):
        raise RuntimeError("device lost")

    brush = Brush(kind="DRAW" if fails == "batched launch" else "SMOOTH", radius=6.0, strength=0.5)
    if fails == "batched launch":
        monkeypatch.setattr(dab_batch, "launch", lost)
    else:
        monkeypatch.setattr(device, "pull_finite", lost)
    path = [(20, 20, 1.0), (50, 40, 1.0)]
    with pytest.raises(RuntimeError, match="device lost"):
        run_stroke(a, brush, path, backend="opencl", device=device)
    assert a.tobytes() == before.tobytes() and device.deferred is None
    on_device = np.empty_like(a)
    opencl.cl.enqueue_copy(opencl.queue, on_device, device.sync())
    assert on_device.tobytes() == a.tobytes()
    monkeypatch.undo()
    run_stroke(a, brush, path, backend="opencl", device=device)
    run_stroke(b, brush, path, backend="numpy")
    assert a.tobytes() == b.tobytes()

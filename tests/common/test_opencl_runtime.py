"""Runtime selection logic (the platform simulated absent) and, in the opencl tier, program build errors and the
build options every program gets."""

import warnings

import numpy as np
import pytest
from tessera.kernels.common import opencl_runtime
from tessera.kernels.common.errors import OpenCLUnavailableError, TesseraError
from tessera.kernels.tessellation import interpolate


@pytest.fixture
def no_platform(monkeypatch):
    def missing():
        raise OpenCLUnavailableError("simulated: no OpenCL platform")

    monkeypatch.setattr(opencl_runtime, "_create", missing)
    yield
    opencl_runtime.configure()


def test_mode_zero_never_touches_opencl(no_platform):
    opencl_runtime.configure(mode="0")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert opencl_runtime.get_runtime() is None


def test_fallback_warns_exactly_once(no_platform):
    opencl_runtime.configure(mode="1")
    with pytest.warns(RuntimeWarning, match="using numpy instead"):
        assert opencl_runtime.get_runtime() is None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert opencl_runtime.get_runtime() is None
        values = np.arange(6, dtype=np.float32).reshape(3, 2)
        out = interpolate.gather_weighted(values, np.array([[0, 2]] * 40000), np.full((40000, 2), 0.5))
    assert np.allclose(out, [2.0, 3.0])


def test_the_fallback_reaches_the_status_bar_once(no_platform):
    """`fallback_notice` (what the guarded operators report as a warning): nothing before the runtime is asked for
    (it never starts OpenCL), one sentence after the fallback, then nothing."""
    opencl_runtime.configure(mode="1")
    assert opencl_runtime.fallback_notice() == ""
    with pytest.warns(RuntimeWarning):
        opencl_runtime.get_runtime()
    notice = opencl_runtime.fallback_notice()
    assert notice.startswith("No OpenCL device was found, so Tessera computes with numpy")
    assert "Troubleshooting" in notice
    assert opencl_runtime.fallback_notice() == ""


def test_require_mode_raises(no_platform):
    opencl_runtime.configure(mode="require")
    with pytest.raises(OpenCLUnavailableError, match="simulated"):
        opencl_runtime.get_runtime()


def test_environment_mode(no_platform, monkeypatch):
    opencl_runtime.configure()
    monkeypatch.setenv("TESSERA_OPENCL", "require")
    with pytest.raises(OpenCLUnavailableError):
        opencl_runtime.get_runtime()
    monkeypatch.setenv("TESSERA_OPENCL", "sometimes")
    with pytest.raises(TesseraError, match="TESSERA_OPENCL must be one of"):
        opencl_runtime.get_runtime()


def test_opencl_backend_refuses_to_fall_back(no_platform):
    opencl_runtime.configure(mode="0")
    with pytest.raises(TesseraError, match="OpenCL backend was requested"):
        interpolate.gather_weighted(np.zeros((2, 1)), np.zeros((1, 1), int), np.ones((1, 1)), backend="opencl")


def test_cache_dir_is_not_in_home(monkeypatch, tmp_path):
    opencl_runtime.configure()
    monkeypatch.delenv("TESSERA_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert opencl_runtime.cache_dir().startswith(str(tmp_path))
    opencl_runtime.configure(cache_dir=str(tmp_path / "prefs"))
    assert opencl_runtime.cache_dir() == str(tmp_path / "prefs")
    opencl_runtime.configure()


@pytest.mark.opencl
def test_build_error_reports_the_compiler_log(opencl, monkeypatch):
    monkeypatch.setitem(opencl_runtime._sources, "broken", "__kernel void k(__global float *x) { x[0] = y; }")
    with pytest.raises(TesseraError, match="failed to build") as err:
        opencl.program("broken")
    assert "y" in str(err.value)


@pytest.mark.opencl
def test_programs_divide_and_take_square_roots_correctly_rounded(opencl, monkeypatch):
    """Every program gets the correctly rounded division and sqrt the numpy references use, where the device has
    them: quotients and roots of random float32 pairs (tiny, huge, near-equal) are the reference's bytes."""
    cl = opencl.cl
    rounded = bool(opencl.device.single_fp_config & cl.device_fp_config.CORRECTLY_ROUNDED_DIVIDE_SQRT)
    assert opencl.base_options == (("-cl-fp32-correctly-rounded-divide-sqrt",) if rounded else ())
    if not rounded:
        return  # a device without them builds with OpenCL's default accuracy (checked just above)
    monkeypatch.setitem(opencl_runtime._sources, "div_sqrt",
                        "__kernel void k(__global const float *a, __global const float *b, __global float *q, "
                        "__global float *r) { int i = get_global_id(0); q[i] = a[i] / b[i]; r[i] = sqrt(a[i]); }")
    rng = np.random.default_rng(3)
    a = (rng.uniform(0.5, 2, 1 << 16) * 10.0 ** rng.integers(-30, 30, 1 << 16)).astype(np.float32)
    b = np.where(rng.random(a.size) < 0.2, a * np.float32(1 + 1e-7), rng.uniform(0.5, 2, a.size) *
                 10.0 ** rng.integers(-30, 30, a.size)).astype(np.float32)
    q, r = np.empty_like(a), np.empty_like(a)
    mf = cl.mem_flags
    bufs = [cl.Buffer(opencl.context, mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=x) for x in (a, b)]
    outs = [cl.Buffer(opencl.context, mf.WRITE_ONLY, a.nbytes) for _ in range(2)]
    opencl.program("div_sqrt").k(opencl.queue, a.shape, None, *bufs, *outs)
    for host, buf in zip((q, r), outs, strict=True):
        cl.enqueue_copy(opencl.queue, host, buf)
    assert q.tobytes() == (a / b).tobytes()
    assert r.tobytes() == np.sqrt(a).tobytes()


def _fake_runtime(build):
    """A `Runtime` whose pyopencl is a stand-in: building a program calls ``build()``, then returns a new object."""
    from types import SimpleNamespace

    class Program:
        def __init__(self, context, source):
            self.source = source

        def build(self, options, cache_dir):
            build()
            return object()

    cl = SimpleNamespace(Program=Program, RuntimeError=RuntimeError,
                         device_fp_config=SimpleNamespace(CORRECTLY_ROUNDED_DIVIDE_SQRT=1))
    device = SimpleNamespace(single_fp_config=0, name="fake", platform=SimpleNamespace(name="fake"))
    return opencl_runtime.Runtime(cl=cl, context=None, queue=None, device=device, cache_dir="")


def test_a_program_asked_for_on_two_threads_is_built_once():
    import threading
    import time

    builds = []
    runtime = _fake_runtime(lambda: (builds.append(1), time.sleep(0.2)))
    got = []
    threads = [threading.Thread(target=lambda: got.append(runtime.program("tubes/tube_body"))) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(builds) == 1
    assert got[0] is got[1] is runtime.program("tubes/tube_body")


def test_configure_while_another_thread_creates_the_runtime_is_never_undone(monkeypatch):
    """A runtime made on a warm-up thread while `configure` runs on another is not kept past the reset: the next
    `get_runtime` makes one with the new settings."""
    import threading
    from types import SimpleNamespace

    inside, release, made = threading.Event(), threading.Event(), []

    def slow_create():
        made.append(SimpleNamespace(description=f"fake {len(made)}"))
        if len(made) == 1:
            inside.set()
            release.wait(5)
        return made[-1]

    monkeypatch.setattr(opencl_runtime, "_create", slow_create)
    opencl_runtime.configure(mode="1")
    try:
        first = threading.Thread(target=opencl_runtime.get_runtime)
        first.start()
        assert inside.wait(5)
        threading.Timer(0.2, release.set).start()  # configure below waits for the creation, then resets
        opencl_runtime.configure(mode="1", device="other")
        first.join()
        assert opencl_runtime.get_runtime() is made[1]
        assert len(made) == 2
    finally:
        release.set()
        opencl_runtime.configure()


def test_warm_up_builds_what_it_can_and_never_raises(monkeypatch, no_platform):
    import threading

    opencl_runtime.configure(mode="require")  # no platform: nothing to warm, and no error escapes
    assert opencl_runtime.warm_up(["tubes/tube_body"]) == []

    built = []

    def build():
        if len(built) == 0 and not hasattr(build, "failed"):
            build.failed = True
            raise RuntimeError("simulated compiler error")
        built.append(1)

    runtime = _fake_runtime(build)
    monkeypatch.setattr(opencl_runtime, "_create", lambda: runtime)
    opencl_runtime.configure(mode="1")
    names = ["terrain/terrain_ham", "tubes/tube_body", "tubes/tube_frames"]
    assert opencl_runtime.warm_up(names) == names[1:]  # the failing build is logged and skipped
    assert {key[0] for key in runtime._programs} == set(names[1:])
    stop = threading.Event()
    stop.set()
    assert opencl_runtime.warm_up(["displacement/map_dabs"], stop) == []
    assert ("displacement/map_dabs", ()) not in runtime._programs


def test_program_names_are_the_shipped_sources():
    names = opencl_runtime.program_names()
    assert {"tubes/tube_body", "tubes/tube_frames", "displacement/map_dabs", "terrain/terrain_ham"} <= set(names)
    assert all((opencl_runtime.KERNELS_DIR / f"{name}.cl").is_file() for name in names)


def test_program_variants_are_every_program_and_the_variants_their_sources_name():
    from tessera.kernels.surfaces import patch_deviation_opencl as pd

    variants = opencl_runtime.program_variants()
    assert [v for v in variants if v[1] == ()] == [(name, ()) for name in opencl_runtime.program_names()]
    # every build Tessellate Surface's measuring asks for (nets of 2 to 7 points a side) is warmed up
    assert {(pd.PROGRAM, pd._options(k)) for k in range(2, 8)} <= set(variants)
    assert len(variants) == len(set(variants))


@pytest.mark.opencl
def test_warm_up_builds_every_shipped_program(opencl):
    """Every program the kernels ship builds on the device, and after `warm_up` asking for one builds nothing."""
    names = opencl_runtime.program_names()
    assert opencl_runtime.warm_up(names) == names
    runtime = opencl_runtime.get_runtime()
    built = dict(runtime._programs)
    assert {(name, ()) for name in names} <= set(built)
    assert all(runtime.program(name) is built[(name, ())] for name in names)
    variants = opencl_runtime.program_variants()  # the variants too: built, then found built
    assert opencl_runtime.warm_up(variants) == variants
    built = dict(runtime._programs)
    assert all(runtime.program(name, options) is built[(name, options)] for name, options in variants)


@pytest.mark.opencl
def test_device_buffers_are_refused_before_the_allocator_can_fail(opencl, monkeypatch):
    """PoCL ends the process when a host allocation fails: every device buffer is checked first, against the
    device's largest allocation and, on a device in host memory, against the memory the system can still give."""
    from tessera.kernels.common import budget
    from tessera.kernels.common.errors import BudgetError

    mf = opencl.cl.mem_flags
    small = opencl.buffer(mf.READ_WRITE, 4096)
    assert small.size == 4096
    largest = int(opencl.device.max_mem_alloc_size)
    with pytest.raises(BudgetError, match="allocates at most"):
        opencl.buffer(mf.READ_WRITE, largest + 1)
    if opencl.host_memory:
        monkeypatch.setattr(budget, "free_bytes", lambda: 2**20)
        with pytest.raises(BudgetError, match="memory is free"):
            opencl.buffer(mf.READ_ONLY | mf.COPY_HOST_PTR, hostbuf=np.zeros(2**19))  # 4 MiB
        # an operation on the device refuses the same way, before any kernel runs
        with pytest.raises(BudgetError, match="memory is free"):
            interpolate.gather_weighted_opencl(opencl, np.zeros((300000, 3), np.float32),
                                               np.zeros((300000, 3), np.int64), np.ones((300000, 3), np.float32))

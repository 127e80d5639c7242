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

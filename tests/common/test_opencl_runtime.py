"""Runtime selection logic (the platform simulated absent) and, in the opencl tier, program build errors."""

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

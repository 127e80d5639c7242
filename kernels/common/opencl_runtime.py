"""OpenCL device selection and program building, with a numpy fallback.

``TESSERA_OPENCL`` selects the mode: ``0`` never uses OpenCL; ``1`` (default) uses it when pyopencl and
a platform are present and otherwise warns once and falls back to numpy; ``require`` raises
`OpenCLUnavailableError` instead of falling back. ``TESSERA_OPENCL_DEVICE`` (or the add-on preference)
is a case-insensitive substring of the wanted device or platform name. Without one, a GPU is preferred.

Programs are read from the ``.cl`` files beside the capability code (``kernels/<capability>/*.cl``, named
``"<capability>/<file>"``) and built once per context (in-process cache; threads asking for a program being built
wait for that build). `warm_up` creates the runtime and builds programs ahead of their first use (the add-on does it
on a background thread once Blender's window is up). Every program is built with
correctly rounded single-precision division and square root where the device offers them: the numpy
references round those correctly, and OpenCL's default allows 2.5-3 ulp (NVIDIA's driver uses it). pyopencl's
binary cache goes to ``TESSERA_CACHE_DIR`` or ``$XDG_CACHE_HOME/tessera``, never a fixed home path.
"""

import logging
import os
import threading
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .budget import check_bytes
from .errors import BudgetError, InvalidInputError, OpenCLUnavailableError, TesseraError
from .typed_kernel import TypedKernel

log = logging.getLogger(__name__)

MODES = ("0", "1", "require")
KERNELS_DIR = Path(__file__).resolve().parents[1]


@dataclass
class _Settings:
    mode: str | None = None  # None: read TESSERA_OPENCL
    device: str | None = None  # None: read TESSERA_OPENCL_DEVICE
    cache_dir: str | None = None  # None: TESSERA_CACHE_DIR or XDG_CACHE_HOME/tessera


@dataclass
class Runtime:
    """A chosen OpenCL device with its context and queue; builds and caches programs."""

    cl: object  # the pyopencl module
    context: object
    queue: object
    device: object
    cache_dir: str
    _programs: dict = field(default_factory=dict)
    _kernels: dict = field(default_factory=dict)
    _building: dict = field(default_factory=dict)  # (name, options) -> lock held while that program builds
    _lock: object = field(default_factory=threading.Lock)

    @property
    def description(self):
        return f"{self.device.platform.name.strip()} / {self.device.name.strip()}"

    @property
    def base_options(self):
        """Build options every program gets: correctly rounded float division and sqrt where the device has
        them (``CL_FP_CORRECTLY_ROUNDED_DIVIDE_SQRT``), as in the numpy references."""
        rounded = self.device.single_fp_config & self.cl.device_fp_config.CORRECTLY_ROUNDED_DIVIDE_SQRT
        return ("-cl-fp32-correctly-rounded-divide-sqrt",) if rounded else ()

    def program(self, name, options=()):
        """Built program for ``kernels/<name>.cl`` (``name`` like ``"tubes/tube_body"``); raises `TesseraError`
        with the compiler log."""
        key = (name, tuple(options))
        prg = self._programs.get(key)
        if prg is not None:
            return prg
        with self._lock:
            building = self._building.setdefault(key, threading.Lock())
        with building:  # another thread building the same program: wait for it instead of building it twice
            if key not in self._programs:
                source = _read_source(name)
                try:
                    prg = self.cl.Program(self.context, source).build(options=[*self.base_options, *options],
                                                                      cache_dir=self.cache_dir)
                except self.cl.RuntimeError as err:
                    raise TesseraError(f"OpenCL program {name}.cl failed to build on {self.description}:\n{err}") \
                        from err
                self._programs[key] = prg
        return self._programs[key]

    @property
    def host_memory(self):
        """Whether the device allocates its buffers in this process's memory (a CPU device such as PoCL)."""
        return bool(self.device.type & self.cl.device_type.CPU) or bool(self.device.host_unified_memory)

    def buffer(self, flags, size=0, hostbuf=None):
        """``cl.Buffer(context, flags, size, hostbuf)``, made only once it can be had: at most the device's largest
        allocation, and on a device that allocates in host memory the bytes the system can still give
        (`budget.free_bytes`: PoCL ends the whole process when its host allocation fails). Raises `BudgetError`
        saying what to change; an allocation the driver refuses anyway becomes one too."""
        nbytes = int(size) if size else int(np.asarray(hostbuf).nbytes) if hostbuf is not None else 0
        largest = int(self.device.max_mem_alloc_size)
        if nbytes > largest:
            raise BudgetError(f"The OpenCL device {self.description} allocates at most {largest / 2**20:,.0f} MiB "
                              f"at once; this needs {nbytes / 2**20:,.0f} MiB. Use smaller settings, or set OpenCL "
                              "to Off in the Tessera preferences")
        if self.host_memory:
            check_bytes(nbytes, 0, "A buffer of the OpenCL device would be made", "smaller settings")
        try:
            return self.cl.Buffer(self.context, flags, size, hostbuf=hostbuf)
        except self.cl.MemoryError as err:
            raise BudgetError(f"The OpenCL device {self.description} could not allocate {nbytes / 2**20:,.0f} MiB "
                              f"({err}). Use smaller settings, or set OpenCL to Off in the Tessera preferences") \
                from err

    def shared(self, host, read_only=False):
        """A buffer on ``host`` memory (``USE_HOST_PTR``: no copy on a CPU device such as PoCL); ``host`` must
        stay alive and contiguous until `sync_to_host` (or the queue finishes)."""
        mf = self.cl.mem_flags
        return self.cl.Buffer(self.context, (mf.READ_ONLY if read_only else mf.READ_WRITE) | mf.USE_HOST_PTR,
                              hostbuf=host)

    def sync_to_host(self, pairs):
        """Wait for the device and make its writes to shared buffers visible: pairs of (buffer, host array)."""
        for buf, host in pairs:
            mapped, _ = self.cl.enqueue_map_buffer(self.queue, buf, self.cl.map_flags.READ, 0, host.shape, host.dtype)
            mapped.base.release(self.queue)
        self.queue.finish()

    def kernel(self, program, name, options=()):
        """A `typed_kernel.TypedKernel` of a program, created once and reused (kernels are not free to retrieve)."""
        key = (program, name, tuple(options))
        if key not in self._kernels:
            self._kernels[key] = TypedKernel(self.cl, self.program(program, options), name)
        return self._kernels[key]


_settings = _Settings()
_state = {"resolved": False, "runtime": None, "warned": False, "why": "", "told": False}
_sources = {}
#: held while the runtime is chosen or the settings change, so a runtime made on one thread (`warm_up`) is never
#: stored after `configure` has reset the choice on another
_choice = threading.RLock()


def _read_source(name):
    if name not in _sources:
        path = KERNELS_DIR / f"{name}.cl"
        if not path.is_file():
            raise TesseraError(f"OpenCL source {path.name} is missing from the installation")
        _sources[name] = path.read_text(encoding="utf-8")
    return _sources[name]


def configure(mode=None, device=None, cache_dir=None):
    """Set the mode, device preference and cache folder (None: from the environment); resets the choice."""
    if mode is not None and mode not in MODES:
        raise TesseraError(f"OpenCL mode must be one of {', '.join(MODES)}; got {mode!r}")
    with _choice:
        _settings.mode, _settings.device, _settings.cache_dir = mode, device, cache_dir
        _state.update(resolved=False, runtime=None, warned=False, why="", told=False)


def current_mode():
    mode = _settings.mode or os.environ.get("TESSERA_OPENCL", "1").strip().lower()
    if mode not in MODES:
        raise TesseraError(f"TESSERA_OPENCL must be one of {', '.join(MODES)}; got {mode!r}")
    return mode


def cache_dir():
    """Folder for compiled-program caches: (str)."""
    if _settings.cache_dir:
        return _settings.cache_dir
    if os.environ.get("TESSERA_CACHE_DIR"):
        return os.environ["TESSERA_CACHE_DIR"]
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "tessera", "pyopencl")


def _pick_device(cl, preference):
    devices = [d for p in cl.get_platforms() for d in p.get_devices()]
    if not devices:
        raise OpenCLUnavailableError("No OpenCL device found (install an ICD, e.g. PoCL: apt install pocl-opencl-icd)")
    if preference:
        wanted = preference.lower()
        for d in devices:
            if wanted in d.name.lower() or wanted in d.platform.name.lower():
                return d
        names = ", ".join(d.name.strip() for d in devices)
        raise OpenCLUnavailableError(f"No OpenCL device matches {preference!r}; available: {names}")
    gpus = [d for d in devices if d.type & cl.device_type.GPU]
    return (gpus or devices)[0]


def _create():
    try:
        import pyopencl as cl
    except ImportError as err:
        raise OpenCLUnavailableError(f"pyopencl is not installed ({err})") from err
    try:
        device = _pick_device(cl, _settings.device or os.environ.get("TESSERA_OPENCL_DEVICE"))
        context = cl.Context([device])
        queue = cl.CommandQueue(context)
    except cl.Error as err:
        raise OpenCLUnavailableError(f"No usable OpenCL platform ({err})") from err
    folder = cache_dir()
    os.makedirs(folder, exist_ok=True)
    return Runtime(cl=cl, context=context, queue=queue, device=device, cache_dir=folder)


def get_runtime():
    """The OpenCL runtime, or None when disabled or unavailable (then numpy is used).

    Raises `OpenCLUnavailableError` only in ``require`` mode. The fallback warning is given once.
    """
    with _choice:
        mode = current_mode()
        if mode == "0":
            return None
        if not _state["resolved"]:
            try:
                _state["runtime"] = _create()
                log.info("Tessera OpenCL device: %s", _state["runtime"].description)
            except OpenCLUnavailableError as err:
                if mode == "require":
                    raise
                _state["runtime"] = None
                _state["why"] = str(err)
                if not _state["warned"]:
                    _state["warned"] = True
                    warnings.warn(f"Tessera: OpenCL unavailable, using numpy instead. {err}", RuntimeWarning,
                                  stacklevel=2)
            _state["resolved"] = True
        if _state["runtime"] is None and mode == "require":
            raise OpenCLUnavailableError("OpenCL is required (TESSERA_OPENCL=require) but unavailable")
        return _state["runtime"]


def fallback_notice():
    """Once after OpenCL was found missing (when the runtime has been asked for; this never starts it): a sentence for
    the user's status bar, else "". The console's warning alone goes unseen in a window."""
    with _choice:
        if not _state["resolved"] or _state["runtime"] is not None or not _state["why"] or _state["told"]:
            return ""
        _state["told"] = True
        return ("No OpenCL device was found, so Tessera computes with numpy on the CPU (slower; the results are the "
                "same). Install an OpenCL driver (PoCL for the CPU, or the GPU's), or see the manual's Troubleshooting")


def program_names():
    """Every program shipped with the kernels (``"<capability>/<file>"`` for ``kernels/*/*.cl``), sorted."""
    return sorted(f"{path.parent.name}/{path.stem}" for path in KERNELS_DIR.glob("*/*.cl"))


#: A line of a program's source that names the build options of its other variants, separated by ``|``
#: (``// build variants: -DK=3 | -DK=5``): programs specialised at build time, which the warm-up builds too.
VARIANTS_LINE = "// build variants:"


def program_variants():
    """Every program shipped with the kernels as it is built without options, ``(name, ())``, and each variant its
    source names on a `VARIANTS_LINE`, ``(name, (option, ...))``: what `warm_up` builds in the add-on."""
    out = []
    for name in program_names():
        out.append((name, ()))
        for line in _read_source(name).splitlines():
            if line.startswith(VARIANTS_LINE):
                out += [(name, tuple(v.split())) for v in line[len(VARIANTS_LINE):].split("|") if v.strip()]
    return out


def warm_up(names, stop=None):
    """Create the runtime and build the programs ``names`` now, so that their first use does not wait for them: each
    a name (built without options) or a ``(name, options)`` pair (`program_variants`).

    For a background thread: never raises (an unavailable device or a failing build is logged, and reported again
    by the first real use). Stops early when ``stop`` (a `threading.Event`) is set or `configure` changes the
    settings meanwhile. Returns the names (or pairs) built (or found built).
    """
    try:
        runtime = get_runtime()
    except TesseraError as err:
        log.info("Tessera OpenCL warm-up skipped: %s", err)
        return []
    if runtime is None:  # OpenCL off or unavailable: nothing to build
        return []
    built = []
    for name in names:
        if (stop is not None and stop.is_set()) or _state["runtime"] is not runtime:
            break
        program, options = (name, ()) if isinstance(name, str) else name
        try:
            runtime.program(program, options)
        except TesseraError as err:
            log.warning("Tessera OpenCL warm-up: %s", err)
            continue
        built.append(name)
    return built


BACKENDS = ("auto", "numpy", "opencl")


def backend_runtime(backend, purpose="this kernel"):
    """The runtime for a ``backend`` choice ("auto", "numpy", "opencl"): None means numpy.

    "opencl" raises `OpenCLUnavailableError` when no device is available; "auto" falls back quietly.
    """
    if backend not in BACKENDS:
        raise InvalidInputError(f"backend must be one of {BACKENDS}; got {backend!r}")
    if backend == "numpy":
        return None
    runtime = get_runtime()
    if runtime is None and backend == "opencl":
        raise OpenCLUnavailableError(f"OpenCL was requested for {purpose} but no device is available")
    return runtime

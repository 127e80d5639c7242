"""OpenSubdiv's Loop refinement through ctypes: the subdivision oracle of the tests and `bench/subdivision.py`.

The shared library is built by ``tools/setup.sh`` (Debian ``libosd-dev``) into ``out/osd/libosd_loop.so``;
`load` says why when it is missing.
"""

import ctypes
from dataclasses import dataclass
from pathlib import Path

import numpy as np

LIBRARY = Path(__file__).resolve().parents[2] / "out" / "osd" / "libosd_loop.so"
SHARPNESS_INFINITE = 10.0
BOUNDARY = {"EDGE_ONLY": 1, "EDGE_AND_CORNER": 2}
FVAR = {"NONE": 0, "CORNERS_ONLY": 1, "CORNERS_PLUS1": 2, "CORNERS_PLUS2": 3, "BOUNDARIES": 4, "ALL": 5}

_lib = None


@dataclass
class OsdResult:
    """Last refinement level: values (V, D) float64, triangles (F, 3) int32, face-varying values (N, W)
    float64 and triangles (F, 3) int32 (None without a channel), seconds of topology and primvar refinement."""

    values: np.ndarray
    triangles: np.ndarray
    fvar_values: np.ndarray | None
    fvar_triangles: np.ndarray | None
    seconds_topology: float
    seconds_primvar: float


def load():
    """The library, or raise `OSError` saying how to build it."""
    global _lib
    if _lib is None:
        if not LIBRARY.exists():
            raise OSError(f"{LIBRARY} is missing: run tools/setup.sh (needs Debian's libosd-dev and g++)")
        lib = ctypes.CDLL(str(LIBRARY))
        p = ctypes.c_void_p
        lib.osd_loop_refine.restype = p
        i = ctypes.c_int
        lib.osd_loop_refine.argtypes = [i, i, p, i, p, i, p, p, i, p, p, i, i, i, i, p, p, i]
        lib.osd_loop_sizes.argtypes = [p, p, p, p, p]
        lib.osd_loop_fetch.argtypes = [p, p, p, p, p]
        lib.osd_loop_free.argtypes = [p]
        _lib = lib
    return _lib


def _ptr(a):
    return None if a is None else a.ctypes.data


def loop_refine(values, triangles, level, creases=None, corners=None, boundary="EDGE_ONLY", fvar=None,
                fvar_interp="BOUNDARIES"):
    """Refine a triangle mesh ``level`` times with OpenSubdiv's Loop scheme.

    values: (V, D) float64 vertex data (positions and anything interpolated like them); triangles: (F, 3) int;
    creases: ``(pairs (K, 2) int, sharpness (K,) float)`` in OpenSubdiv units (10 = infinitely sharp) or None;
    corners: ``(vertices (C,) int, sharpness (C,) float)`` or None;
    fvar: ``(values (N, W) float64, indices (F, 3) int)`` one face-varying channel or None.
    """
    lib = load()
    values = np.ascontiguousarray(values, np.float64)
    if values.ndim == 1:
        values = values[:, None]
    tris = np.ascontiguousarray(triangles, np.int32)
    pairs, sharp = (np.zeros((0, 2), np.int32), np.zeros(0, np.float32)) if creases is None else creases
    pairs = np.ascontiguousarray(pairs, np.int32)
    sharp = np.ascontiguousarray(sharp, np.float32)
    cv, cs = (np.zeros(0, np.int32), np.zeros(0, np.float32)) if corners is None else corners
    cv = np.ascontiguousarray(cv, np.int32)
    cs = np.ascontiguousarray(cs, np.float32)
    fv, fi = (None, None) if fvar is None else fvar
    if fv is not None:
        fv = np.ascontiguousarray(fv, np.float64)
        fi = np.ascontiguousarray(fi, np.int32)
    handle = lib.osd_loop_refine(
        len(values), len(tris), _ptr(tris), values.shape[1], _ptr(values), len(pairs), _ptr(pairs), _ptr(sharp),
        len(cv), _ptr(cv), _ptr(cs),
        BOUNDARY[boundary], int(level), 0 if fv is None else fv.shape[1], 0 if fv is None else len(fv),
        _ptr(fi), _ptr(fv), FVAR[fvar_interp])
    if not handle:
        raise ValueError("OpenSubdiv refused the topology")
    try:
        n_v, n_f, n_fv = (ctypes.c_int(), ctypes.c_int(), ctypes.c_int())
        seconds = np.zeros(2)
        lib.osd_loop_sizes(handle, ctypes.byref(n_v), ctypes.byref(n_f), ctypes.byref(n_fv), _ptr(seconds))
        out_v = np.empty((n_v.value, values.shape[1]))
        out_t = np.empty((n_f.value, 3), np.int32)
        out_fv = None if fv is None else np.empty((n_fv.value, fv.shape[1]))
        out_ft = None if fv is None else np.empty((n_f.value, 3), np.int32)
        lib.osd_loop_fetch(handle, _ptr(out_v), _ptr(out_t), _ptr(out_fv), _ptr(out_ft))
    finally:
        lib.osd_loop_free(handle)
    return OsdResult(out_v, out_t, out_fv, out_ft, float(seconds[0]), float(seconds[1]))

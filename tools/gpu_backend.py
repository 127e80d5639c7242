"""Run the ``bpy`` module's GPU on Vulkan (Mesa's lavapipe, set up by tools/setup.sh in out/vulkan) for the gpu tier's
Vulkan run: ``TESSERA_GPU_BACKEND=VULKAN`` makes the tests' first import of bpy call `use_vulkan`.

The module fixes its backend from factory preferences at import, reads no command line or environment variable for
it, and has no Python API to change it. What works: after ``import bpy`` and before the first GPU context, call
Blender's own ``GPU_backend_type_selection_set_override`` and ``GPU_backend_type_selection_set`` with Vulkan. They
are local symbols of ``bpy/__init__.so``: their offsets come from its symbol table (``nm``), the load address from an
exported symbol's address (``PyInit_bpy``). The caller checks the result with ``gpu.platform.backend_type_get()``.
"""

import ctypes
import importlib.util
import os
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LAVAPIPE_ICD = ROOT / "out" / "vulkan" / "lvp_icd.json"
#: ``GPUBackendType::VULKAN`` (the value of VULKAN in ``PreferencesSystem.gpu_backend``).
VULKAN = 8
_SYMBOLS = ("PyInit_bpy", "_ZN7blender39GPU_backend_type_selection_set_overrideENS_14GPUBackendTypeE",
            "_ZN7blender30GPU_backend_type_selection_setENS_14GPUBackendTypeE")


def use_vulkan():
    """Select Vulkan for the bpy module of this process (call after ``import bpy``, before any GPU context). Raises
    RuntimeError saying what is missing."""
    if not os.environ.get("VK_ICD_FILENAMES"):
        if not LAVAPIPE_ICD.is_file():
            raise RuntimeError(f"no Vulkan driver: {LAVAPIPE_ICD} is missing (tools/setup.sh unpacks Mesa's lavapipe)")
        os.environ["VK_ICD_FILENAMES"] = str(LAVAPIPE_ICD)
    so = importlib.util.find_spec("bpy").origin
    try:
        listing = subprocess.run(["nm", so], capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError) as err:
        raise RuntimeError(f"cannot read bpy's symbol table with nm ({err})") from err
    offsets = {}
    for line in listing.splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[2] in _SYMBOLS:
            offsets[parts[2]] = int(parts[0], 16)
    if len(offsets) != len(_SYMBOLS):
        raise RuntimeError(f"bpy's symbol table lacks {sorted(set(_SYMBOLS) - set(offsets))}")
    lib = ctypes.CDLL(so)
    base = ctypes.cast(lib.PyInit_bpy, ctypes.c_void_p).value - offsets["PyInit_bpy"]
    for name in _SYMBOLS[1:]:
        ctypes.CFUNCTYPE(None, ctypes.c_int)(base + offsets[name])(VULKAN)

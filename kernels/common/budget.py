"""The memory guard every operator shares: the size of a result estimated before the work, checked by `check_bytes`
against the budget the user set (Tessera preferences) and against the memory the system can still give this
process (`free_bytes`: an address-space limit such as ``ulimit -v``, and the RAM and swap the kernel reports
available), so a request that cannot fit is refused before anything is allocated, never ended by the allocator
(numpy's MemoryError, or PoCL's abort when its host allocation fails)."""

import os
from dataclasses import dataclass

from .errors import BudgetError


@dataclass(frozen=True)
class Estimate:
    """Output size of a run, computed without running it: vertices, triangles, peak bytes."""

    vertices: int
    triangles: int
    bytes: int


def _proc_kib(path, key):
    """A ``key:  N kB`` line of a /proc file, in KiB, or None."""
    try:
        with open(path, encoding="ascii") as f:
            for line in f:
                if line.startswith(key + ":"):
                    return int(line.split()[1])
    except (OSError, ValueError, IndexError):
        return None
    return None


def _system_memory():
    """(available RAM + free swap, virtual size this process maps now) in bytes, from psutil (bundled with the
    extension: Linux, Windows and macOS alike), else from /proc (Linux); None for what the system does not say."""
    try:
        import psutil
    except ImportError:
        psutil = None
    if psutil is not None:
        try:
            available = psutil.virtual_memory().available + psutil.swap_memory().free
            mapped = psutil.Process().memory_info().vms
            return available, mapped
        except (OSError, RuntimeError, AttributeError):
            pass
    available, swap = _proc_kib("/proc/meminfo", "MemAvailable"), _proc_kib("/proc/meminfo", "SwapFree")
    mapped = _proc_kib(f"/proc/{os.getpid()}/status", "VmSize")
    return (None if available is None else (available + (swap or 0)) * 1024,
            None if mapped is None else mapped * 1024)


def free_bytes():
    """Bytes this process can still allocate as far as the system tells: the address-space limit (``ulimit -v``)
    less what the process maps now, and the available memory plus free swap; the smaller of the two, or None where
    the system says nothing."""
    available, mapped = _system_memory()
    limits = [] if available is None else [available]
    try:
        import resource

        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
        if soft != resource.RLIM_INFINITY and mapped is not None:
            limits.append(soft - mapped)
    except (ImportError, OSError, ValueError):  # Windows: no address-space limit to read
        pass
    return max(0, min(limits)) if limits else None


def check_bytes(need, budget_bytes, what, lower):
    """Raise `BudgetError` when ``need`` bytes exceed ``budget_bytes`` (0 or None: no limit) or the memory the system
    can still give (`free_bytes`). ``what`` says what is made ("The tubes would have about 3,000,000 vertices"),
    ``lower`` what to change ("fewer sides")."""
    need = int(need)
    if budget_bytes and need > budget_bytes:
        raise BudgetError(f"{what} and need about {need / 2**20:,.0f} MiB, over the memory budget of "
                          f"{budget_bytes / 2**20:,.0f} MiB. Use {lower}, or raise the budget in the Tessera "
                          "preferences.")
    free = free_bytes()
    if free is not None and need > free:
        raise BudgetError(f"{what} and need about {need / 2**20:,.0f} MiB, but only {free / 2**20:,.0f} MiB of "
                          f"memory is free for Blender now. Use {lower}, or close other programs.")
    return need


def check_budget(est, budget_bytes, lower="a lower level"):
    """`check_bytes` for an `Estimate` of triangles; ``lower`` names the change to make."""
    return check_bytes(est.bytes, budget_bytes, f"The result would have {est.triangles:,} triangles", lower)

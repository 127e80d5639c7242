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


def free_bytes():
    """Bytes this process can still allocate as far as the system tells: the address-space limit less what the
    process maps now, and the kernel's available memory plus free swap; the smaller of the two, or None where the
    system says nothing (not Linux, no limit and no /proc)."""
    limits = []
    try:
        import resource

        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
        if soft != resource.RLIM_INFINITY:
            mapped = _proc_kib(f"/proc/{os.getpid()}/status", "VmSize")
            if mapped is not None:
                limits.append(soft - mapped * 1024)
    except (ImportError, OSError, ValueError):
        pass
    available, swap = _proc_kib("/proc/meminfo", "MemAvailable"), _proc_kib("/proc/meminfo", "SwapFree")
    if available is not None:
        limits.append((available + (swap or 0)) * 1024)
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

"""Transparent huge pages for large arrays written once, start to end (Linux).

The first write to new memory costs the operating system a page fault for every 4 KiB page: a tube mesh of a
gigabyte or more is hundreds of thousands of faults, most of what ``tessera.tubes`` waits for. Advised with
``MADV_HUGEPAGE``, a range is backed by 2 MiB pages where the kernel has them: 512 times fewer faults. numpy advises
every array of 4 MiB and more this way; Blender's own arrays are not advised, so `addon.mesh_memory` advises a new
mesh's large arrays (`advise`) before they are written. ``bench/tubes.py`` (``operator_huge_pages``) measures the
operator with huge pages on and off; ``docs/performance.md`` keeps the figures.

Where it is not done (`enabled`):
- ``/sys/kernel/mm/transparent_hugepage/enabled`` says ``[never]``, or the system is not Linux;
- the machine is a virtual machine that reports free memory to its hypervisor (`reports_free_pages`: a virtio
  balloon with free page reporting, or Hyper-V's balloon driver). Such a guest hands 2 MiB blocks that stayed free
  for a few seconds back to the host, and the next huge page there costs the host a fault for every 4 KiB in it:
  slower than small pages, which come from the guest's own fragments first, which it keeps.

``TESSERA_HUGE_PAGES`` = ``on`` / ``off`` / ``auto`` (the default) overrides that choice.
"""

import ctypes
import functools
import os
import sys
from pathlib import Path

#: Arrays smaller than this are not advised (numpy's threshold for its own arrays).
MIN_BYTES = 4 << 20
#: The huge page size the advice is aligned to (x86-64 and arm64 with 4 KiB base pages).
HUGE_PAGE = 2 << 20
MADV_HUGEPAGE = 14
#: virtio device id of the memory balloon, and its feature bit for free page reporting (virtio spec 5.5.3).
VIRTIO_BALLOON_ID = 0x0005
VIRTIO_BALLOON_F_REPORTING = 5


def enabled():
    """Whether `advise` asks for huge pages in this process: ``TESSERA_HUGE_PAGES`` (on/off), else `auto_choice`."""
    mode = os.environ.get("TESSERA_HUGE_PAGES", "auto").strip().lower()
    if mode in ("on", "1", "true"):
        return sys.platform.startswith("linux")
    if mode in ("off", "0", "false"):
        return False
    return auto_choice()


@functools.lru_cache(maxsize=1)
def auto_choice():
    """Huge pages on Linux when the kernel offers them and the machine does not report free memory to a host."""
    if not sys.platform.startswith("linux"):
        return False
    root = Path("/sys")
    return thp_offered(root) and not reports_free_pages(root)


def thp_offered(sys_root):
    """Whether transparent huge pages are ``always`` or ``madvise`` under ``sys_root`` (a ``/sys`` tree)."""
    try:
        setting = (Path(sys_root) / "kernel/mm/transparent_hugepage/enabled").read_text()
    except OSError:
        return False
    return "[always]" in setting or "[madvise]" in setting


def reports_free_pages(sys_root):
    """Whether this machine hands free memory back to a hypervisor (see the module docstring): a virtio balloon
    offering free page reporting, or a bound Hyper-V balloon driver, under ``sys_root`` (a ``/sys`` tree)."""
    root = Path(sys_root)
    for device in sorted((root / "bus/virtio/devices").glob("*")):
        try:
            kind = int((device / "device").read_text().strip(), 16)
            features = (device / "features").read_text().strip()
        except (OSError, ValueError):
            continue
        if kind == VIRTIO_BALLOON_ID and features[VIRTIO_BALLOON_F_REPORTING:VIRTIO_BALLOON_F_REPORTING + 1] == "1":
            return True
    try:  # a bound device is a link in its driver's folder
        return any(p.is_symlink() for p in (root / "bus/vmbus/drivers/hv_balloon").iterdir())
    except OSError:  # no Hyper-V balloon driver
        return False


def advise(address, nbytes):
    """Ask for huge pages on the whole 2 MiB pages inside [address, address + nbytes) of private anonymous memory
    (an array not yet written). Does nothing for fewer than `MIN_BYTES` or where `enabled` says no. Returns True
    when the advice was taken."""
    if nbytes < MIN_BYTES or not enabled():
        return False
    lo = -(-address // HUGE_PAGE) * HUGE_PAGE
    hi = (address + nbytes) // HUGE_PAGE * HUGE_PAGE
    if hi <= lo:
        return False
    madvise = _libc_madvise()
    return madvise is not None and madvise(lo, hi - lo, MADV_HUGEPAGE) == 0


@functools.lru_cache(maxsize=1)
def _libc_madvise():
    try:
        fn = ctypes.CDLL(None, use_errno=True).madvise
    except (OSError, AttributeError):
        return None
    fn.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int]
    fn.restype = ctypes.c_int
    return fn


def vm_flags(address):
    """The kernel's flags of the mapping that holds ``address`` in this process (``/proc/self/smaps`` VmFlags, such
    as ``hg`` for a range advised with `MADV_HUGEPAGE`): a set of two-letter codes, empty where it cannot be read."""
    try:
        with open("/proc/self/smaps") as smaps:
            inside = False
            for line in smaps:
                head = line.split(maxsplit=1)[0]
                if "-" in head and not head.endswith(":"):
                    lo, hi = (int(x, 16) for x in head.split("-"))
                    inside = lo <= address < hi
                elif inside and head == "VmFlags:":
                    return set(line.split()[1:])
    except (OSError, ValueError):
        pass
    return set()

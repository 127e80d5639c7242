"""The memory guard: the user's budget and the memory the system can still give, checked before any allocation."""

import subprocess
import sys

import pytest
from conftest import REPO_DIR
from tessera.kernels.common import budget
from tessera.kernels.common.errors import BudgetError


def test_the_budget_and_the_free_memory_each_refuse_with_their_numbers(monkeypatch):
    monkeypatch.setattr(budget, "free_bytes", lambda: 3 * 2**20)
    assert budget.check_bytes(2 * 2**20, 0, "It would have 5 things", "fewer things") == 2 * 2**20
    with pytest.raises(BudgetError, match=r"It would have 5 things and need about 10 MiB, over the memory budget of "
                                          r"4 MiB\. Use fewer things, or raise the budget"):
        budget.check_bytes(10 * 2**20, 4 * 2**20, "It would have 5 things", "fewer things")
    with pytest.raises(BudgetError, match=r"need about 4 MiB, but only 3 MiB of memory is free .* Use fewer things"):
        budget.check_bytes(4 * 2**20, 0, "It would have 5 things", "fewer things")
    monkeypatch.setattr(budget, "free_bytes", lambda: None)  # a system that says nothing: the budget alone
    assert budget.check_bytes(2**40, 0, "It", "less") == 2**40


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc and RLIMIT_AS are Linux facts")
def test_free_memory_follows_an_address_space_limit():
    code = (
        "import resource, sys\n"
        f"sys.path.insert(0, {str(REPO_DIR)!r})\n"
        "from tessera.kernels.common import budget\n"
        "before = budget.free_bytes()\n"
        "mapped = budget._proc_kib('/proc/self/status', 'VmSize') * 1024\n"
        "resource.setrlimit(resource.RLIMIT_AS, (mapped + 300 * 2**20, resource.RLIM_INFINITY))\n"
        "print(before, budget.free_bytes())\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120)
    before, after = (int(v) for v in out.stdout.split())
    assert before > 300 * 2**20 and 250 * 2**20 < after <= 300 * 2**20


class _FakePsutil:
    """psutil as a system with ``available`` bytes of RAM, ``swap`` free, this process mapping ``mapped``."""

    def __init__(self, available, swap, mapped):
        from types import SimpleNamespace

        self.virtual_memory = lambda: SimpleNamespace(available=available)
        self.swap_memory = lambda: SimpleNamespace(free=swap)
        self.Process = lambda: SimpleNamespace(memory_info=lambda: SimpleNamespace(vms=mapped))


def test_free_memory_comes_from_psutil_on_a_system_without_proc(monkeypatch):
    """Windows and macOS have no /proc: the bundled psutil says what is free, and a low-memory system refuses."""
    monkeypatch.setattr(budget, "_proc_kib", lambda path, key: None)  # no /proc
    monkeypatch.setitem(sys.modules, "psutil", _FakePsutil(available=200 * 2**20, swap=56 * 2**20, mapped=2**30))
    assert budget.free_bytes() == 256 * 2**20
    with pytest.raises(BudgetError, match=r"need about 300 MiB, but only 256 MiB of memory is free"):
        budget.check_bytes(300 * 2**20, 0, "It would have 5 things", "fewer things")
    assert budget.check_bytes(200 * 2**20, 0, "It would have 5 things", "fewer things") == 200 * 2**20


def test_without_psutil_linux_reads_proc_and_other_systems_say_nothing(monkeypatch):
    monkeypatch.setitem(sys.modules, "psutil", None)  # import psutil fails
    if sys.platform.startswith("linux"):
        assert budget.free_bytes() > 0
    monkeypatch.setattr(budget, "_proc_kib", lambda path, key: None)
    import resource

    if resource.getrlimit(resource.RLIMIT_AS)[0] == resource.RLIM_INFINITY:
        assert budget.free_bytes() is None  # nothing known: the user's budget alone decides


def test_psutil_and_proc_agree_here():
    pytest.importorskip("psutil")
    if not sys.platform.startswith("linux"):
        pytest.skip("/proc is Linux's")
    import psutil

    proc = (budget._proc_kib("/proc/meminfo", "MemAvailable") + budget._proc_kib("/proc/meminfo", "SwapFree")) * 1024
    ours = psutil.virtual_memory().available + psutil.swap_memory().free
    assert abs(ours - proc) < 0.05 * proc + 64 * 2**20

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

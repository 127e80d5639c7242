"""The memory guard every mesh-making kernel shares: an `Estimate` of the output computed before the work, and
`check_budget` against the budget the user set (Tessera preferences)."""

from dataclasses import dataclass

from .errors import BudgetError


@dataclass(frozen=True)
class Estimate:
    """Output size of a run, computed without running it: vertices, triangles, peak bytes."""

    vertices: int
    triangles: int
    bytes: int


def check_budget(est, budget_bytes, lower="the level"):
    """Raise `BudgetError` when an `Estimate` exceeds ``budget_bytes`` (0 or None: no limit); ``lower`` names the
    setting to lower."""
    if budget_bytes and est.bytes > budget_bytes:
        raise BudgetError(
            f"The result would have {est.triangles:,} triangles and need about {est.bytes / 2**20:,.0f} MiB, "
            f"over the memory budget of {budget_bytes / 2**20:,.0f} MiB. Lower {lower}, or raise the "
            f"budget in the Tessera preferences."
        )

"""The result object of a discrete solve."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from .._checks import FloatArray

__all__ = ["STATUSES", "DiscreteSolution"]

#: Closed set of ``DiscreteSolution.status`` values and their meaning.
STATUSES: dict[str, str] = {
    "optimal": "globally optimal: the relaxation is exact (or there are no jerk rows)",
    "refined": "feasible local optimum from IPOPT; the optimum lies in [lower_bound, objective]",
    "scaled": "feasible point obtained by scaling the relaxed w down (refinement failed); "
    "the optimum lies in [lower_bound, objective]",
    "relaxed": "relaxation only (refine='never'): w violates some jerk rows (see jerk_violation)",
}


@dataclass(frozen=True)
class DiscreteSolution:
    """Solution of the discrete problem with its optimality certificate.

    Attributes
    ----------
    w : ndarray, shape (n,)
        Squared speed at the grid nodes.
    objective : float
        True objective ``Σ h / sqrt(w_i)`` of the returned ``w`` (the travel time).
    lower_bound : float
        Certified lower bound on the optimum: the relaxation's dual objective.
    gap : float
        ``(objective - lower_bound) / lower_bound``; 0 up to solver tolerance when exact.
    exact : bool
        Whether the relaxed ``w`` met every jerk row (paper's test, violation <= 1e-5).
    exact_a_priori : bool
        Whether Corollary 1 certified exactness before solving (constant bounds, ``w_max``
        meeting every positive jerk row).
    jerk_violation : float
        Largest jerk-row violation of the returned ``w`` (paper's measure, ``h = 1`` units).
    refined : bool
        Whether the nonconvex refinement ran.
    status : str
        One of :data:`STATUSES`.
    solve_time : float
        Wall time of the whole solve [s].
    extras : dict
        Backend details: ``backend``, ``iterations``, ``relaxation_time``, ``refine_time``,
        ``refine_status``, ``relaxed_w``, ``relaxed_jerk_violation``.
    """

    w: FloatArray
    objective: float
    lower_bound: float
    gap: float
    exact: bool
    exact_a_priori: bool
    jerk_violation: float
    refined: bool
    status: str
    solve_time: float
    extras: dict[str, Any] = field(default_factory=dict)

    @property
    def feasible(self) -> bool:
        """Whether ``w`` satisfies every row of the original problem (within tolerance)."""
        return self.status != "relaxed"

    def __repr__(self) -> str:
        return (
            f"DiscreteSolution(status={self.status!r}, objective={self.objective:.9g}, "
            f"lower_bound={self.lower_bound:.9g}, gap={self.gap:.3g}, exact={self.exact}, "
            f"n={self.w.size}, solve_time={self.solve_time:.3g}s)"
        )

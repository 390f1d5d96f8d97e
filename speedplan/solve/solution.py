"""The typed result objects of a discrete solve."""

from __future__ import annotations

from dataclasses import KW_ONLY, dataclass
from typing import Literal

from ..core.checks import FloatArray

__all__ = ["STATUSES", "DiscreteSolution", "RefinementInfo", "RelaxationInfo", "Status"]

#: ``DiscreteSolution.status``: a closed set of values.
Status = Literal["optimal", "refined", "scaled", "relaxed"]

#: What each `Status` means.
STATUSES: dict[str, str] = {
    "optimal": "globally optimal: the relaxation is exact (or there are no jerk rows)",
    "refined": "feasible local optimum from IPOPT; the optimum lies in [lower_bound, objective]",
    "scaled": "feasible point obtained by scaling the relaxed w down (refinement failed); "
    "the optimum lies in [lower_bound, objective]",
    "relaxed": "relaxation only (refine='never'): w violates some jerk rows (see jerk_violation)",
}


@dataclass(frozen=True)
class RelaxationInfo:
    """How the convex relaxation was solved.

    Attributes
    ----------
    backend : str
        The backend that produced the answer: ``"clarabel"`` or ``"banded"``.
    status : str
        That backend's own status (``"Solved"``, ``"AlmostSolved"``).
    iterations : int
        Interior-point iterations.
    time : float
        Setup and solve time [s].
    w : ndarray
        The relaxed ``w``, clipped to its bounds (the refinement starts from it).
    jerk_violation : float
        Largest jerk-row violation of ``w`` (``<= jerk_tol``: the relaxation is exact).
    fallback : str or None
        Why the first backend tried was abandoned, or ``None`` when it answered.
    cut_bound : float or None
        The lower bound of the relaxation with the stencil rows' secant cuts
        (`speedplan.solve.cuts`) [s], solved when the relaxation was not exact and its gap
        large; ``None`` when not solved (or when it failed).
    cut_time : float
        Setup and solve time of that relaxation [s] (0 when not solved).
    """

    backend: str
    status: str
    iterations: int
    time: float
    w: FloatArray
    jerk_violation: float
    fallback: str | None = None
    cut_bound: float | None = None
    cut_time: float = 0.0


@dataclass(frozen=True)
class RefinementInfo:
    """How the nonconvex refinement (CasADi + IPOPT) went.

    Attributes
    ----------
    status : str
        IPOPT's return status.
    accepted : bool
        Whether our own checks found its point feasible (it is then the returned ``w`` when
        the relaxation was not exact).
    iterations : int
        IPOPT iterations.
    time : float
        Wall time including building the NLP [s].
    objective : float or None
        Travel time of the refined point when accepted.
    """

    status: str
    accepted: bool
    iterations: int
    time: float
    objective: float | None


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
        Whether the relaxed ``w`` met every jerk (and lateral-jerk) row: the paper's test
        (violation <= 1e-5) and within `ROW_TOL_REL` (1 %) of each row's own bound.
    exact_a_priori : bool
        Whether Corollary 1 certified exactness before solving (constant bounds, ``w_max``
        meeting every positive jerk row).
    jerk_violation : float
        Largest jerk-row violation of the returned ``w`` (paper's measure, ``h = 1`` units).
    refined : bool
        Whether the nonconvex refinement ran.
    status : str
        One of `STATUSES`.
    solve_time : float
        Wall time of the whole solve [s].
    backend : str
        ``"pass"`` (no jerk rows: the exact forward/backward pass), ``"clarabel"`` or
        ``"banded"``.
    relaxation : RelaxationInfo or None
        Details of the relaxation (``None`` for the pass).
    refinement : RefinementInfo or None
        Details of the refinement when it ran.
    """

    w: FloatArray
    objective: float
    lower_bound: float
    gap: float
    exact: bool
    exact_a_priori: bool
    jerk_violation: float
    refined: bool
    status: Status
    solve_time: float
    backend: str
    _: KW_ONLY  # the details below are passed by name
    relaxation: RelaxationInfo | None = None
    refinement: RefinementInfo | None = None

    @property
    def feasible(self) -> bool:
        """Whether ``w`` satisfies every row of the original problem (within tolerance)."""
        return self.status != "relaxed"

    @property
    def message(self) -> str:
        """What [`status`][speedplan.DiscreteSolution] means."""
        return STATUSES[self.status]

    def __repr__(self) -> str:
        return (
            f"DiscreteSolution(status={self.status!r}, objective={self.objective:.9g}, "
            f"lower_bound={self.lower_bound:.9g}, gap={self.gap:.3g}, exact={self.exact}, "
            f"n={self.w.size}, solve_time={self.solve_time:.3g}s)"
        )

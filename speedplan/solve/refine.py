"""The refinement step: a feasible point of the original problem near the relaxed ``w``.

`refine` runs the banded interior-point method (`speedplan.solve.banded_nlp`) from
each of its `STARTS` and keeps the best point the caller's
acceptance test passes; only when none passes does it run IPOPT
(`refine_ipopt`). The problem is nonconvex, so different starts
can end in different local optima (up to 3 % apart on the benchmark corpus): the best of the
starts is the safeguard. Each run costs a few milliseconds per thousand nodes, and the last
start is skipped when the first two agree; given the relaxation's certified lower bound, the
starts end at the first accepted point within `ENOUGH_GAP` of it. Problems with lateral-jerk
rows run `LATERAL_STARTS` instead, and end at the first accepted one (the best of the starts
there on every refinement measured).

A run that stops short of convergence (its iteration limit, a failed restoration) at a point
the caller accepts within `ENOUGH_GAP` of the bound answers when no converged run is
accepted, and IPOPT does not run: next to a stop, the starts can end at their iteration
limit 3.6e-5 above the bound, where IPOPT then ran its 5 s to fail. Farther from the bound
such points are not used: next to stops they were up to 12 % above it, one with a law at 5
times the jerk limit.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from ..core.checks import FloatArray
from ..core.deadline import passed
from .banded_nlp import LATERAL_STARTS, STARTS, solve_banded_nlp
from .ipopt_ import RefineResult, refine_ipopt
from .problem import GRIP_TOL, DiscreteProblem

__all__ = ["AGREE", "ENOUGH_GAP", "refine"]

#: Two runs whose travel times agree to this (relative) ended at the same local optimum; the
#: remaining start is then skipped. On the benchmark corpus (150 instances) this skipped it on
#: 124 and never lost a better optimum; agreeing runs differ by about 1e-8 (their tolerance).
AGREE = 1e-7
#: An accepted run whose travel time lies within this (relative) of a certified lower bound
#: ends the starts: no other start can be faster by more. (Problems with lateral rows end at
#: their first accepted start anyway, see `LATERAL_STARTS`.)
ENOUGH_GAP = 1e-4


def refine(
    problem: DiscreteProblem, w0: FloatArray,
    accept: Callable[[FloatArray], bool] | None = None,
    lower_bound: float | None = None,
    ipopt: bool = True,
) -> RefineResult:
    """Refine the relaxed ``w0`` into a feasible point of the original problem.

    Parameters
    ----------
    problem : DiscreteProblem
        The problem, best in the units `solve_banded_nlp`
        asks for.
    w0 : ndarray, shape (n,)
        The relaxed ``w``.
    accept : callable, optional
        ``accept(w) -> bool``, the caller's feasibility test of a candidate ``w`` (full grid,
        problem units). By default a candidate must meet the rows within
        `DiscreteProblem.jerk_tol` and its bounds to ``1e-9 max(w_max)``.
    lower_bound : float, optional
        A certified lower bound on ``problem``'s travel time (the relaxation's): the starts
        end at the first accepted candidate within `ENOUGH_GAP` of it.
    ipopt : bool
        Whether IPOPT runs when no banded start is accepted (for up to 5 s).

    Returns
    -------
    RefineResult
        The accepted candidate of least travel time, ``success=True`` (the starts are run in
        order until two accepted ones agree to `AGREE`, or one lies within `ENOUGH_GAP` of
        ``lower_bound``; with lateral rows, until one is accepted), or else an accepted point
        within `ENOUGH_GAP` of ``lower_bound`` that a run stopped short of convergence at; if
        none is accepted, the last
        candidate with ``success=False``. ``status`` names the solver and its start,
        ``iterations`` and ``solve_time`` cover every run.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.solve import DiscreteProblem
    >>> from speedplan.solve.refine import refine
    >>> p = DiscreteProblem(s=np.linspace(0.0, 1.0, 21), w_max=np.ones(21), accel=np.full(20, 4.0),
    ...                     decel=np.full(20, 4.0), jerk=np.full(19, 8.0))
    >>> res = refine(p, np.full(21, 0.5))
    >>> res.success, res.status.startswith("banded/")
    (True, True)
    >>> bool(p.jerk_violation(res.w) <= p.jerk_tol)
    True
    """
    t0 = time.perf_counter()
    if accept is None:
        accept = _default_acceptance(problem)
    best: tuple[float, FloatArray, str] | None = None
    unconverged: tuple[float, FloatArray, str] | None = None  # the best the caller accepts
    last: tuple[FloatArray, str] = (np.asarray(w0, dtype=np.float64), "not run")
    iterations = 0
    found: list[float] = []
    # The banded method holds no friction-ellipse rows: IPOPT refines those problems.
    starts = () if problem.has_grip else LATERAL_STARTS if problem.has_lateral else STARTS
    first_wins = problem.has_lateral
    for start in starts:
        if iterations and passed():  # the plan's deadline (speedplan.core.deadline): stop
            break
        res = solve_banded_nlp(problem, w0, start)
        iterations += res.iterations
        status = f"banded/{start.name}: {res.status}"
        last = (res.w, status)
        if res.success and accept(res.w):
            objective = problem.travel_time(res.w)
            if best is None or objective < best[0]:
                best = (objective, res.w, status)
            if first_wins:
                break
            if lower_bound is not None and objective <= lower_bound * (1.0 + ENOUGH_GAP):
                break  # certified within ENOUGH_GAP: no start can gain more
            if any(abs(objective - f) <= AGREE * f for f in found):
                break  # two paths ended at the same point: the third would too (corpus)
            found.append(objective)
        elif not res.success and accept(res.w):
            objective = problem.travel_time(res.w)
            if unconverged is None or objective < unconverged[0]:
                unconverged = (objective, res.w, status)
    if best is None and unconverged is not None and lower_bound is not None and (
            unconverged[0] <= lower_bound * (1.0 + ENOUGH_GAP)):
        best = unconverged  # feasible and certified near the optimum: IPOPT cannot gain more
    if best is None and ipopt and not passed():
        fallback = refine_ipopt(problem, w0)
        iterations += fallback.iterations
        status = f"ipopt: {fallback.status}"
        if fallback.success and accept(fallback.w):
            best = (problem.travel_time(fallback.w), fallback.w, status)
        last = (fallback.w, status)
    if best is None:
        return RefineResult(w=last[0], status=last[1], success=False, iterations=iterations,
                            solve_time=time.perf_counter() - t0)
    return RefineResult(w=best[1], status=best[2], success=True, iterations=iterations,
                        solve_time=time.perf_counter() - t0)


def _default_acceptance(problem: DiscreteProblem) -> Callable[[FloatArray], bool]:
    """The problem's own row checks with a tolerance relative to its largest bound."""
    tol = 1e-9 * max(1.0, float(np.max(problem.w_max)))

    def accept(w: FloatArray) -> bool:
        return bool(problem.linear_violation(w) <= tol
                    and problem.jerk_violation(w) <= problem.jerk_tol
                    and problem.grip_violation(w) <= GRIP_TOL)

    return accept

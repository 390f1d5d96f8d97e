"""Local refinement of the original (nonconvex) problem with CasADi + IPOPT.

Started from the relaxed ``w``, IPOPT searches a feasible point of the true problem with
jerk-type rows ``|c_i · w_{i-1:i+2}| sqrt(w_i) <= B_i``. Its answer is re-checked by our own
code (`DiscreteProblem.jerk_violation`, `DiscreteProblem.linear_violation`), never
trusted. `speedplan.solve.refine.refine` runs it when the banded interior-point method
(`speedplan.solve.banded_nlp`) returns no acceptable point.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.checks import FloatArray
from ..core.deadline import remaining
from ..core.errors import SolverError
from .problem import DiscreteProblem

__all__ = ["IPOPT_MAX_SECONDS", "IPOPT_OPTIONS", "RefineResult", "refine_ipopt"]

#: IPOPT's defaults (monotone barrier update, gradient-based scaling, bound_push 1e-2) with
#: tolerances tight enough for our acceptance test. Measured on the benchmark corpus (150
#: instances, ``benchmarks/bench_refine.py``): the adaptive barrier update with rows divided
#: by their bound, used before, reported Infeasible_Problem_Detected on 10 instances the
#: defaults solved; the default tolerance 1e-8 leaves rows violated beyond our tolerance on a
#: quarter of them. Successful runs took at most 133 iterations.
IPOPT_OPTIONS: dict[str, Any] = {
    "print_level": 0,
    "sb": "yes",
    "tol": 1e-10,
    "constr_viol_tol": 1e-10,
    "acceptable_tol": 1e-8,
    "max_iter": 300,
}
#: Longest IPOPT run [s], whatever the plan's time limit. Successful runs take well under a
#: second on the corpus; a run whose linear solves degenerate (MUMPS reallocating its memory
#: at every factorisation, seen on a state read off a plan's final stop: 7 s per iteration,
#: 300 iterations allowed) would otherwise take most of an hour.
IPOPT_MAX_SECONDS = 5.0
#: Building the NLP: CasADi's extra functions for parametric sensitivities and multipliers
#: are not needed and cost more than half of the build at n = 4000.
NLPSOL_OPTIONS: dict[str, Any] = {"print_time": False, "no_nlp_grad": True, "calc_lam_p": False}


@dataclass(frozen=True)
class RefineResult:
    """Raw result of one refinement (``w`` on the full grid, in the problem's units).

    Attributes
    ----------
    w : ndarray, shape (n,)
        The refined point, ends included.
    status : str
        The solver's status: IPOPT's return status from `refine_ipopt`; from
        `refine`, the solver that produced ``w`` and its status,
        e.g. ``"banded/near: Solved"`` or ``"ipopt: Solve_Succeeded"``.
    success : bool
        Whether the solver converged (and, from `refine`,
        whether the caller's acceptance test passed).
    iterations : int
        Iterations, summed over every run made.
    solve_time : float
        Wall time including building the NLP [s].
    """

    w: FloatArray
    status: str
    success: bool
    iterations: int
    solve_time: float


def _rows(problem: DiscreteProblem, x: Any) -> tuple[Any, FloatArray, FloatArray]:
    """Every row as one CasADi column: acceleration, then each jerk-type family."""
    import casadi as ca
    w_full = ca.vertcat(problem.w_start, x, problem.w_end)
    parts = [w_full[1:] - w_full[:-1]]
    lbg, ubg = [-problem.decel * problem.h], [problem.accel * problem.h]
    for family in problem.stencil_families():  # jerk rows, then lateral-jerk rows
        finite = np.flatnonzero(np.isfinite(family.bound))
        if not finite.size:
            continue
        coef = np.asarray(family.coef)[finite]
        if finite.size == problem.n - 2:  # vectorised slices: far faster to build than indexing
            w0, w1, w2 = w_full[:-2], x, w_full[2:]
        else:
            k = finite.tolist()
            w0, w1, w2 = w_full[k], x[k], w_full[(finite + 2).tolist()]
        load = ca.DM(coef[:, 0]) * w0 + ca.DM(coef[:, 1]) * w1 + ca.DM(coef[:, 2]) * w2
        parts.append(load * ca.sqrt(w1))
        lbg.append(-family.bound[finite])
        ubg.append(family.bound[finite])
    return ca.vertcat(*parts), np.concatenate(lbg), np.concatenate(ubg)


def _grip_rows(problem: DiscreteProblem, x: Any, u: Any) -> tuple[Any, FloatArray, FloatArray]:
    """Friction-ellipse rows with the cells' acceleration fractions ``u`` as variables.

    ``u_i >= ±(w_{i+1} - w_i) / (h A)`` keeps the rows smooth (``max`` is not).
    """
    import casadi as ca

    assert problem.grip is not None
    w_full = ca.vertcat(problem.w_start, x, problem.w_end)
    dw = w_full[1:] - w_full[:-1]
    g = ca.DM(problem.grip)
    lat = g * w_full
    k = problem.n - 1
    rows = ca.vertcat(u - dw / ca.DM(problem.h * problem.accel),
                      u + dw / ca.DM(problem.h * problem.decel),
                      u * u + lat[:-1] * lat[:-1], u * u + lat[1:] * lat[1:])
    lbg = np.concatenate((np.zeros(2 * k), np.full(2 * k, -np.inf)))
    ubg = np.concatenate((np.full(2 * k, np.inf), np.ones(2 * k)))
    return rows, lbg, ubg


def refine_ipopt(problem: DiscreteProblem, w0: FloatArray) -> RefineResult:
    """Run IPOPT on the original problem from ``w0`` (interior nodes free, ends fixed).

    The rows are the plain ones, ``(c · w) sqrt(w_i) ∈ [-B_i, B_i]``; IPOPT scales them.

    Raises
    ------
    SolverError
        If CasADi or IPOPT fails to run at all (an unsuccessful run is returned, not raised).

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.solve import DiscreteProblem
    >>> from speedplan.solve.ipopt_ import refine_ipopt
    >>> n = 21
    >>> p = DiscreteProblem(s=np.linspace(0.0, 1.0, n), w_max=np.ones(n),
    ...                     accel=np.full(n - 1, 4.0), decel=np.full(n - 1, 4.0),
    ...                     jerk=np.full(n - 2, 8.0))
    >>> res = refine_ipopt(p, np.full(n, 0.5))
    >>> res.success, bool(p.jerk_violation(res.w) <= p.jerk_tol)
    (True, True)
    """
    # casadi is imported here, not at module level: it costs ~0.3 s and most plans never
    # reach this fallback (``import speedplan`` must not load it).
    import casadi as ca

    t0 = time.perf_counter()
    m = problem.n - 2
    wmin = 1e-9 * max(1.0, float(np.max(problem.w_max)))
    x = ca.SX.sym("w", m)
    g, lbg, ubg = _rows(problem, x)
    ub = problem.w_max[1:-1]
    lb = np.minimum(wmin, ub)
    if problem.w_min is not None:
        lb = np.maximum(lb, problem.w_min[1:-1])
    x0 = np.clip(w0[1:-1], lb, ub)
    variables = x
    if problem.grip is not None:
        u = ca.SX.sym("u", problem.n - 1)
        grip, glb, gub = _grip_rows(problem, x, u)
        g, lbg, ubg = ca.vertcat(g, grip), np.concatenate((lbg, glb)), np.concatenate((ubg, gub))
        variables = ca.vertcat(x, u)
        w_start = np.concatenate(([problem.w_start], x0, [problem.w_end]))
        dw = np.diff(w_start)
        u0 = np.clip(np.maximum(dw / (problem.h * problem.accel),
                                -dw / (problem.h * problem.decel)), 0.0, 1.0)
        x0, lb, ub = (np.concatenate((x0, u0)), np.concatenate((lb, np.zeros(u0.size))),
                      np.concatenate((ub, np.ones(u0.size))))
    nlp = {"x": variables, "f": ca.dot(ca.DM(problem.tau), 1.0 / ca.sqrt(x)), "g": g}
    try:
        left = remaining()  # the plan's deadline (speedplan.core.deadline), if any
        wall = IPOPT_MAX_SECONDS if left is None else min(left, IPOPT_MAX_SECONDS)
        options = {**IPOPT_OPTIONS, "max_wall_time": wall}
        solver = ca.nlpsol("refine", "ipopt", nlp, {"ipopt": options, **NLPSOL_OPTIONS})
        sol = solver(x0=x0, lbx=lb, ubx=ub, lbg=lbg, ubg=ubg)
    except RuntimeError as exc:
        raise SolverError(f"IPOPT failed to run: {exc}", backend="ipopt") from exc
    stats = solver.stats()
    w = np.concatenate(([problem.w_start], np.asarray(sol["x"]).ravel()[:m], [problem.w_end]))
    return RefineResult(
        w=w,
        status=str(stats.get("return_status", "unknown")),
        success=bool(stats.get("success", False)),
        iterations=int(stats.get("iter_count", -1)),
        solve_time=time.perf_counter() - t0,
    )

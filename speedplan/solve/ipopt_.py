"""Local refinement of the original (nonconvex) problem with CasADi + IPOPT.

Started from the relaxed ``w``, IPOPT searches a feasible point of the true problem with
jerk rows ``|w''_i| sqrt(w_i) <= J_i``. Its answer is re-checked by our own code
(:meth:`DiscreteProblem.jerk_violation`, :meth:`DiscreteProblem.linear_violation`), never trusted.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from ..core.checks import FloatArray
from ..core.errors import SolverError
from .problem import DiscreteProblem

__all__ = ["RefineResult", "refine_ipopt"]

#: IPOPT options: printing off, tight tolerances (the problem is scaled to O(1) before).
IPOPT_OPTIONS: dict[str, Any] = {
    "print_level": 0,
    "sb": "yes",
    "tol": 1e-10,
    "constr_viol_tol": 1e-10,
    "acceptable_tol": 1e-8,
    "max_iter": 3000,
    "mu_strategy": "adaptive",
}


@dataclass(frozen=True)
class RefineResult:
    """Raw result of one refinement."""

    w: FloatArray
    status: str
    success: bool
    iterations: int
    solve_time: float


def refine_ipopt(problem: DiscreteProblem, w0: FloatArray) -> RefineResult:
    """Run IPOPT on the original problem from ``w0`` (interior nodes free, ends fixed).

    Jerk rows are normalised as ``w''_i sqrt(w_i) / J_i ∈ [-1, 1]`` so every row is O(1).
    """
    t0 = time.perf_counter()
    n = problem.n
    m = n - 2
    wmin = 1e-9 * max(1.0, float(np.max(problem.w_max)))
    x = ca.SX.sym("w", m)
    w_full = ca.vertcat(problem.w_start, x, problem.w_end)
    tau = ca.DM(problem.tau)
    f = ca.sum1(tau / ca.sqrt(x))
    dw = w_full[1:] - w_full[:-1]
    g_parts = [dw]
    lbg = [-problem.decel * problem.h]
    ubg = [problem.accel * problem.h]
    for family in problem.stencil_families():  # jerk rows, then lateral-jerk rows
        finite = np.flatnonzero(np.isfinite(family.bound))
        if not finite.size:
            continue
        stencil = ca.DM(problem.stencil_matrix(family.coef)[finite].tocsc())
        load = ca.mtimes(stencil, w_full)
        xs = x[finite.tolist()] if finite.size < m else x
        g_parts.append(load * ca.sqrt(xs) / ca.DM(family.bound[finite]))
        lbg.append(-np.ones(finite.size))
        ubg.append(np.ones(finite.size))
    nlp = {"x": x, "f": f, "g": ca.vertcat(*g_parts)}
    try:
        solver = ca.nlpsol("refine", "ipopt", nlp, {"ipopt": IPOPT_OPTIONS, "print_time": False})
        ub = problem.w_max[1:-1]
        lb = np.minimum(wmin, ub)
        if problem.w_min is not None:
            lb = np.maximum(lb, problem.w_min[1:-1])
        start = np.clip(w0[1:-1], lb, ub)
        sol = solver(
            x0=start, lbx=lb, ubx=ub, lbg=np.concatenate(lbg),
            ubg=np.concatenate(ubg),
        )
    except RuntimeError as exc:
        raise SolverError(f"IPOPT failed to run: {exc}", backend="ipopt") from exc
    stats = solver.stats()
    w = np.concatenate(([problem.w_start], np.asarray(sol["x"]).ravel(), [problem.w_end]))
    return RefineResult(
        w=w,
        status=str(stats.get("return_status", "unknown")),
        success=bool(stats.get("success", False)),
        iterations=int(stats.get("iter_count", -1)),
        solve_time=time.perf_counter() - t0,
    )

"""Refinement step: IPOPT (as speedplan runs it) against CasADi's structure-exploiting fatrop.

What it measures
----------------
When the SOCP relaxation is not exact, speedplan refines its ``w`` with a local NLP solver on the
original (nonconvex) problem (``speedplan/solve/ipopt_.py``). This script solves that refinement
NLP on the same instances, from the same start, with

``ipopt``
    speedplan's own :func:`~speedplan.solve.ipopt_.refine_ipopt`, unchanged (exact Hessian,
    ``IPOPT_OPTIONS``).
``fatrop``
    CasADi's ``fatrop`` plugin (Riccati-based interior point) on a stage-wise rewrite of the same
    NLP: stage ``k = 1..n-2`` has the state ``x_k = (w_{k-1}, w_k)`` and the control
    ``u_k = w_{k+1}``; the dynamics ``x_{k+1} = (x_k[1], u_k)`` are the gap-closing rows; each
    stage carries the same acceleration row and the same normalised jerk row
    ``w''_k sqrt(w_k) / J_k in [-1, 1]`` as speedplan's IPOPT NLP. Only copies of ``w`` are added.
``fatrop-slope``
    fatrop on the other natural stage-wise form: ``x_k = (w_k, sigma_{k-1})`` with the slope
    ``sigma_k = (w_{k+1} - w_k) / h_k``, control ``u_k = sigma_k - sigma_{k-1}``. Acceleration
    rows become bounds on ``sigma``; the jerk row is ``u_k sqrt(w_k) / (tau_k J_k)`` (exact on any
    grid since ``w''_k = (sigma_k - sigma_{k-1}) / tau_k``).

Instances are :func:`speedplan.solve.paper.paper_instance` draws (default family
``("rnd", "cnst", "logrnd")``, strongly varying ``J``, where the relaxation is not exact), seeds
``seed, seed + 1, ...``. The start is the relaxed ``w`` of ``solve_discrete(..., refine="never")``
(``relaxation.w``); every solver works on the problem scaled to unit ``h`` and ``w_max``
exactly as ``solve_problem`` does, and every answer is re-checked by speedplan's own code on the
original problem: ``ok`` is speedplan's acceptance test for a refinement (solver success, jerk
violation <= ``jerk_tol``, linear violation <= the linear tolerance, after the same clipping into
``[0, w_max]``).

Columns: objective ``sum tau_i / sqrt(w_i)``; gap to the relaxation's certified lower bound;
largest jerk-row violation (:meth:`DiscreteProblem.jerk_violation`, tolerance ``jerk_tol``) and
linear-row violation (:meth:`DiscreteProblem.linear_violation`); wall time split into ``build``
(symbolic NLP and ``casadi.nlpsol`` construction; for ``ipopt`` only the ``casadi.nlpsol``
call made inside ``refine_ipopt``, timed by wrapping it, so its few-ms symbolic setup counts as
solve) and ``solve`` (the rest). ``fail`` counts
runs where the solver reports failure or raises; ``infeas`` counts runs it reports as solved but
whose ``w`` fails the check.

Two things to know about fatrop 1.1.8 inside CasADi 3.8.2. It relaxes every inequality bound by
``1e-8 * max(1, |bound|)`` and the factor is not an option the CasADi plugin accepts, so bounds
are tightened by that amount before the call (without it ``w`` overshoots ``w_max`` by 1e-8 and
speedplan's clipping turns that into jerk violations of about 2e-6, a fifth of ``jerk_tol``).
And the construction ``casadi.nlpsol(..., "fatrop", ...)`` grows quadratically with the horizon
(with ``structure_detection`` ``"auto"`` or ``"manual"`` alike), which the ``build`` column
shows; the ``solve only`` ratio is what a solver built once per grid size and reused (data
passed as parameters) could reach.

Usage::

    python benchmarks/bench_refine.py --sizes 200 1000 2000 --instances 5 --seed 0
"""

from __future__ import annotations

import argparse
import contextlib
import os
import statistics
import time
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from speedplan import solve_discrete
from speedplan.core.checks import FloatArray
from speedplan.core.errors import SolverError, SpeedplanWarning
from speedplan.solve.discrete import _linear_tol  # speedplan's own acceptance tolerance
from speedplan.solve.ipopt_ import IPOPT_OPTIONS, refine_ipopt
from speedplan.solve.paper import paper_instance
from speedplan.solve.problem import DiscreteProblem

#: fatrop options mirroring speedplan's IPOPT_OPTIONS (fatrop's names differ; it rejects unknown
#: names such as ``acceptable_tol`` or ``mu_strategy``).
FATROP_OPTIONS: dict[str, Any] = {
    "print_level": 0,
    "tolerance": IPOPT_OPTIONS["tol"],
    "constr_viol_tol": IPOPT_OPTIONS["constr_viol_tol"],
    "tol_acceptable": IPOPT_OPTIONS["acceptable_tol"],
    "max_iter": IPOPT_OPTIONS["max_iter"],
}
#: fatrop's fixed bound relaxation (``bound_relax_factor_`` in its IpNlpOrig; not settable).
FATROP_BOUND_RELAX = 1e-8
#: Names of fatrop's ``IpSolverReturnFlag`` values (``stats["fatrop"]["return_flag"]``).
FATROP_FLAGS = (
    "Success", "MaxIterExceeded", "StopAtAcceptablePoint", "LocalInfeasibility",
    "LineSearchFailed", "ErrorInStepComputation", "Unknown",
)
SOLVERS = ("ipopt", "fatrop", "fatrop-slope")


@dataclass(frozen=True)
class Case:
    """One instance: the original problem, its unit-scaled copy and the relaxed start."""

    seed: int
    problem: DiscreteProblem
    unit: DiscreteProblem
    w_scale: float
    w0: FloatArray  # relaxed w in unit scale
    lower_bound: float
    relaxed_violation: float


@dataclass(frozen=True)
class Run:
    """What one solver returned on one case (``w`` in unit scale, ``None`` if it raised)."""

    solver: str
    status: str
    success: bool
    iterations: int
    w: FloatArray | None
    build: float
    solve: float


@dataclass(frozen=True)
class Row:
    """A run checked on the original problem."""

    n: int
    seed: int
    run: Run
    ok: bool
    objective: float
    gap: float
    jerk_violation: float
    linear_violation: float

    @property
    def total(self) -> float:
        """Wall time of the whole refinement call."""
        return self.run.build + self.run.solve


def make_case(family: tuple[str, str, str], n: int, seed: int) -> Case:
    """Draw an instance and relax it with speedplan (the start both solvers share)."""
    inst = paper_instance(*family, n=n, seed=seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SpeedplanWarning)  # "relaxation not exact": expected
        sol = solve_discrete(inst.w_max, inst.A, inst.J, refine="never")
    # The problem solve_discrete builds, and its scaling as in solve_problem.
    problem = DiscreteProblem(
        s=np.arange(n, dtype=np.float64), w_max=inst.w_max, accel=inst.A, decel=inst.A,
        jerk=inst.J,
    )
    w_scale = float(np.max(problem.w_max))
    unit = problem.scaled(float(np.mean(problem.h)), w_scale)
    return Case(
        seed=seed, problem=problem, unit=unit, w_scale=w_scale,
        w0=np.asarray(sol.relaxation.w) / w_scale, lower_bound=sol.lower_bound,
        relaxed_violation=float(sol.relaxation.jerk_violation),
    )


def check(n: int, case: Case, run: Run) -> Row:
    """Apply speedplan's acceptance test for a refinement (``solve_problem``) to ``run``."""
    p = case.problem
    if run.w is None or not np.all(np.isfinite(run.w)):
        nan = float("nan")
        return Row(n, case.seed, run, False, nan, nan, nan, nan)
    w = np.clip(run.w * case.w_scale, 0.0, p.w_max)
    jv, lv = p.jerk_violation(w), p.linear_violation(w)
    ok = run.success and lv <= _linear_tol(p) and jv <= p.jerk_tol
    obj = p.travel_time(w)
    gap = (obj - case.lower_bound) / case.lower_bound
    return Row(n, case.seed, run, ok, obj, gap, jv, lv)


# --- IPOPT: speedplan's own function ----------------------------------------------------------


@contextlib.contextmanager
def _timed_nlpsol() -> Iterator[list[float]]:
    """Record how long each ``casadi.nlpsol`` construction takes while the context is open."""
    original = ca.nlpsol
    times: list[float] = []

    def timed(*args: Any, **kwargs: Any) -> Any:
        t0 = time.perf_counter()
        try:
            return original(*args, **kwargs)
        finally:
            times.append(time.perf_counter() - t0)

    ca.nlpsol = timed
    try:
        yield times
    finally:
        ca.nlpsol = original


def run_ipopt(unit: DiscreteProblem, w0: FloatArray) -> Run:
    """speedplan's refinement, unchanged; build = its ``nlpsol`` construction."""
    t0 = time.perf_counter()
    with _timed_nlpsol() as build_times:
        try:
            res = refine_ipopt(unit, w0)
        except SolverError as exc:
            total = time.perf_counter() - t0
            return Run("ipopt", f"error: {exc}", False, -1, None, sum(build_times),
                       total - sum(build_times))
    total = time.perf_counter() - t0
    build = sum(build_times)
    return Run("ipopt", res.status, res.success, res.iterations, res.w, build, total - build)


# --- fatrop: stage-wise formulations ----------------------------------------------------------


def _tighten(lo: FloatArray, hi: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Undo fatrop's bound relaxation on every finite, non-fixed bound."""
    lo, hi = lo.astype(np.float64), hi.astype(np.float64)
    free = lo < hi
    m = free & np.isfinite(lo)
    lo[m] += FATROP_BOUND_RELAX * np.maximum(1.0, np.abs(lo[m]))
    m = free & np.isfinite(hi)
    hi[m] -= FATROP_BOUND_RELAX * np.maximum(1.0, np.abs(hi[m]))
    return lo, hi


def _w_bounds(p: DiscreteProblem) -> tuple[FloatArray, FloatArray]:
    """Bounds on every node's ``w`` as ``refine_ipopt`` sets them on the interior."""
    wmin = 1e-9 * max(1.0, float(np.max(p.w_max)))
    ub = p.w_max.astype(np.float64)
    lb = np.minimum(wmin, ub)
    if p.w_min is not None:
        lb = np.maximum(lb, p.w_min)
    return lb, ub


def _inv_jerk(p: DiscreteProblem) -> FloatArray:
    """``1 / J`` with ``0`` for absent rows (the row is then ``0 in [-1, 1]``)."""
    with np.errstate(divide="ignore"):
        return np.where(np.isfinite(p.jerk), 1.0 / p.jerk, 0.0)


@dataclass(frozen=True)
class StageNlp:
    """A stage-ordered NLP for fatrop with its bounds, start and ``w`` extraction."""

    x: ca.SX
    f: ca.SX
    g: ca.SX
    equality: list[bool]
    lbx: FloatArray
    ubx: FloatArray
    lbg: FloatArray
    ubg: FloatArray
    x0: FloatArray
    stages: int
    extract: Callable[[FloatArray], FloatArray]


def lift_nlp(p: DiscreteProblem, w0: FloatArray) -> StageNlp:
    """Lifted form: ``x_k = (w_{k-1}, w_k)``, ``u_k = w_{k+1}`` (``k = 1..n-2``).

    The terminal stage ``n-1`` has the state ``(w_{n-2}, w_{n-1})`` and no control.

    Variable order ``[x_1, u_1, x_2, u_2, ..., x_{n-2}, u_{n-2}, x_{n-1}]``; row order per stage:
    the two gap-closing rows ``x_{k+1} - (x_k[1], u_k)``, then the acceleration row
    ``w_k - w_{k-1}`` and the jerk row of node ``k``; last, the terminal acceleration row.
    """
    n, m = p.n, p.n - 2
    v = ca.SX.sym("v", 3 * m + 2)
    z = ca.reshape(v[: 3 * m], 3, m)  # column k-1 = (w_{k-1}, w_k, w_{k+1}) of stage k
    x_last = v[3 * m:]
    prev, cur, nxt = z[0, :], z[1, :], z[2, :]
    gap = ca.horzcat(z[0:2, 1:], x_last) - ca.vertcat(cur, nxt)
    d2 = p.second_difference
    idx = np.arange(m)[:, None]
    coef = np.asarray(d2[idx, idx + np.arange(3)[None, :]].todense())  # (m, 3)
    wpp = (ca.DM(coef[:, 0]).T * prev + ca.DM(coef[:, 1]).T * cur
           + ca.DM(coef[:, 2]).T * nxt)
    jerk = wpp * ca.sqrt(cur) * ca.DM(_inv_jerk(p)).T
    rows = ca.vertcat(gap, cur - prev, jerk)
    g = ca.vertcat(ca.vec(rows), x_last[1] - x_last[0])
    f = ca.dot(ca.DM(p.tau), ca.vec(1.0 / ca.sqrt(cur)))

    zeros, ones = np.zeros(m), np.ones(m)
    lo_a, hi_a = -p.decel * p.h, p.accel * p.h
    lbg = np.concatenate((np.column_stack((zeros, zeros, lo_a[:m], -ones)).ravel(), lo_a[m:]))
    ubg = np.concatenate((np.column_stack((zeros, zeros, hi_a[:m], ones)).ravel(), hi_a[m:]))
    lb, ub = _w_bounds(p)
    inf = np.full(m, np.inf)
    lbx = np.concatenate((np.column_stack((-inf, lb[1:-1], -inf)).ravel(), [-np.inf, p.w_end]))
    ubx = np.concatenate((np.column_stack((inf, ub[1:-1], inf)).ravel(), [np.inf, p.w_end]))
    lbx[0] = ubx[0] = p.w_start
    w = np.clip(w0, lb, ub)
    w[0], w[-1] = p.w_start, p.w_end
    x0 = np.concatenate((np.column_stack((w[:-2], w[1:-1], w[2:])).ravel(), w[-2:]))

    def extract(xv: FloatArray) -> FloatArray:
        return np.concatenate(([p.w_start], xv[1 : 3 * m : 3], [p.w_end]))

    equality = [True, True, False, False] * m + [False]
    return StageNlp(v, f, g, equality, lbx, ubx, lbg, ubg, x0, n - 2, extract)


def slope_nlp(p: DiscreteProblem, w0: FloatArray) -> StageNlp:
    """Slope form: ``x_k = (w_k, sigma_{k-1})``, ``u_k = sigma_k - sigma_{k-1}``.

    States for ``k = 0..n-1`` (``sigma_{-1} = 0`` fixed), controls for ``k = 0..n-2``.

    Dynamics ``w_{k+1} = w_k + h_k (sigma_{k-1} + u_k)``, ``sigma_k = sigma_{k-1} + u_k``;
    acceleration rows are the state bounds ``-D_k <= sigma_k <= A_k``; stage ``k = 1..n-2``
    carries the jerk row ``u_k sqrt(w_k) / (tau_k J_k)``.
    """
    n, m, stages = p.n, p.n - 2, p.n - 1
    v = ca.SX.sym("v", 3 * stages + 2)
    z = ca.reshape(v[: 3 * stages], 3, stages)
    x_last = v[3 * stages:]
    w_k, s_prev, u = z[0, :], z[1, :], z[2, :]
    s_new = s_prev + u
    gap = (ca.horzcat(z[0:2, 1:], x_last)
           - ca.vertcat(w_k + ca.DM(p.h).T * s_new, s_new))
    jerk = u[:, 1:] * ca.sqrt(w_k[:, 1:]) * ca.DM(_inv_jerk(p) / p.tau).T
    g = ca.vertcat(gap[:, 0], ca.vec(ca.vertcat(gap[:, 1:], jerk)))
    f = ca.dot(ca.DM(p.tau), ca.vec(1.0 / ca.sqrt(w_k[:, 1:])))

    zeros, ones = np.zeros(m), np.ones(m)
    lbg = np.concatenate(([0.0, 0.0], np.column_stack((zeros, zeros, -ones)).ravel()))
    ubg = np.concatenate(([0.0, 0.0], np.column_stack((zeros, zeros, ones)).ravel()))
    lb, ub = _w_bounds(p)
    lo_s = np.concatenate(([0.0], -p.decel))
    hi_s = np.concatenate(([0.0], p.accel))
    inf = np.full(stages, np.inf)
    lbx = np.concatenate((np.column_stack((lb[:-1], lo_s[:-1], -inf)).ravel(), [p.w_end, lo_s[-1]]))
    ubx = np.concatenate((np.column_stack((ub[:-1], hi_s[:-1], inf)).ravel(), [p.w_end, hi_s[-1]]))
    lbx[0] = ubx[0] = p.w_start
    w = np.clip(w0, lb, ub)
    w[0], w[-1] = p.w_start, p.w_end
    sigma = np.diff(w) / p.h
    s0 = np.concatenate(([0.0], sigma[:-1]))
    x0 = np.concatenate((np.column_stack((w[:-1], s0, sigma - s0)).ravel(), [w[-1], sigma[-1]]))

    def extract(xv: FloatArray) -> FloatArray:
        return np.concatenate(([p.w_start], xv[3 : 3 * stages : 3], [p.w_end]))

    equality = [True, True] + [True, True, False] * m
    return StageNlp(v, f, g, equality, lbx, ubx, lbg, ubg, x0, n - 1, extract)


def run_fatrop(name: str, build_nlp: Callable[[DiscreteProblem, FloatArray], StageNlp],
               unit: DiscreteProblem, w0: FloatArray) -> Run:
    """Build the stage-wise NLP, let CasADi detect its OCP structure, solve with fatrop."""
    t0 = time.perf_counter()
    try:
        nlp = build_nlp(unit, w0)
        solver = ca.nlpsol(
            "refine_" + name.replace("-", "_"), "fatrop", {"x": nlp.x, "f": nlp.f, "g": nlp.g},
            {"structure_detection": "auto", "equality": nlp.equality, "print_time": False,
             "fatrop": FATROP_OPTIONS},
        )
    except RuntimeError as exc:
        return Run(name, f"build error: {str(exc).strip().splitlines()[-1]}", False, -1, None,
                   time.perf_counter() - t0, 0.0)
    t1 = time.perf_counter()
    lbx, ubx = _tighten(nlp.lbx, nlp.ubx)
    lbg, ubg = _tighten(nlp.lbg, nlp.ubg)
    try:
        sol = solver(x0=nlp.x0, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg)
    except RuntimeError as exc:
        return Run(name, f"solve error: {str(exc).strip().splitlines()[-1]}", False, -1, None,
                   t1 - t0, time.perf_counter() - t1)
    stats = solver.stats()
    w = nlp.extract(np.asarray(sol["x"]).ravel())
    t2 = time.perf_counter()
    flag = int(stats.get("fatrop", {}).get("return_flag", len(FATROP_FLAGS) - 1))
    status = FATROP_FLAGS[flag] if 0 <= flag < len(FATROP_FLAGS) else f"flag {flag}"
    if int(stats.get("N", -1)) != nlp.stages:  # structure detection found something else
        status += f" (N={stats.get('N')}, expected {nlp.stages})"
    return Run(name, status, bool(stats.get("success", False)),
               int(stats.get("iter_count", -1)), w, t1 - t0, t2 - t1)


RUNNERS: dict[str, Callable[[DiscreteProblem, FloatArray], Run]] = {
    "ipopt": run_ipopt,
    "fatrop": lambda unit, w0: run_fatrop("fatrop", lift_nlp, unit, w0),
    "fatrop-slope": lambda unit, w0: run_fatrop("fatrop-slope", slope_nlp, unit, w0),
}


# --- report -----------------------------------------------------------------------------------


def _median(xs: list[float]) -> float:
    return statistics.median(xs) if xs else float("nan")


def _total(r: Row) -> float:
    return r.total


def _solve(r: Row) -> float:
    return r.run.solve


def _build(r: Row) -> float:
    return r.run.build


def print_row(r: Row) -> None:
    """One line of the per-run table (a long error status is printed in full above it)."""
    status = r.run.status
    if len(status) > 60:
        print(f"# n={r.n} seed={r.seed} {r.run.solver}: {status}")
        status = status[:57] + "..."
    print(f"| {r.n} | {r.seed} | {r.run.solver} | {status} | {'yes' if r.ok else 'NO'} "
          f"| {r.run.iterations} | {r.objective:.9g} | {100 * r.gap:.3g} "
          f"| {r.jerk_violation:.2e} | {r.linear_violation:.2e} "
          f"| {r.run.build:.3f} | {r.run.solve:.3f} | {r.total:.3f} |", flush=True)


def print_summary(rows: list[Row], solvers: list[str], sizes: list[int]) -> None:
    """Per size and solver: reliability counts and median times; time ratios ipopt/fatrop."""
    print("\n## Summary (medians over instances; times in s)")
    print("| n | solver | ok | fail | infeas | median iters | median build | median solve "
          "| median total | obj/obj_ipopt - 1: min, max |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    ipopt_obj = {(r.n, r.seed): r.objective for r in rows if r.run.solver == "ipopt" and r.ok}
    for n in sizes:
        for s in solvers:
            rs = [r for r in rows if r.n == n and r.run.solver == s]
            if not rs:
                continue
            fail = sum(not r.run.success for r in rs)
            infeas = sum(r.run.success and not r.ok for r in rs)
            diffs = [r.objective / ipopt_obj[(n, r.seed)] - 1.0 for r in rs
                     if r.ok and (n, r.seed) in ipopt_obj]
            diff = f"{min(diffs):.1e}, {max(diffs):.1e}" if diffs else "-"
            print(f"| {n} | {s} | {sum(r.ok for r in rs)}/{len(rs)} | {fail} | {infeas} "
                  f"| {_median([r.run.iterations for r in rs]):g} "
                  f"| {_median([r.run.build for r in rs]):.3f} "
                  f"| {_median([r.run.solve for r in rs]):.3f} "
                  f"| {_median([r.total for r in rs]):.3f} | {diff} |")
    others = [s for s in solvers if s != "ipopt"]
    if "ipopt" not in solvers or not others:
        return
    print("\n## Time ratio ipopt / fatrop: ratio of medians over the instances both solved ok "
          "(> 1: fatrop faster)")
    print("| n | solver | instances | total (build + solve) | solve only | build only |")
    print("|---|---|---|---|---|---|")
    for n in sizes:
        ip = {r.seed: r for r in rows if r.n == n and r.run.solver == "ipopt" and r.ok}
        for s in others:
            fr = {r.seed: r for r in rows if r.n == n and r.run.solver == s and r.ok}
            both = sorted(ip.keys() & fr.keys())
            if not both:
                print(f"| {n} | {s} | 0 | - | - | - |")
                continue
            ratios = [
                _median([get(ip[k]) for k in both]) / _median([get(fr[k]) for k in both])
                for get in (_total, _solve, _build)
            ]
            print(f"| {n} | {s} | {len(both)} | " + " | ".join(f"{x:.2f}" for x in ratios) + " |")


def main(argv: list[str] | None = None) -> None:
    """Run the comparison and print the tables."""
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[200, 1000, 2000])
    ap.add_argument("--instances", type=int, default=5, help="instances per size")
    ap.add_argument("--seed", type=int, default=0, help="first seed (then seed+1, ...)")
    ap.add_argument("--family", nargs=3, default=["rnd", "cnst", "logrnd"],
                    metavar=("W", "A", "J"), help="paper_instance family")
    ap.add_argument("--solvers", nargs="+", choices=SOLVERS, default=list(SOLVERS))
    args = ap.parse_args(argv)

    solvers = list(args.solvers)
    has_fatrop = ca.has_nlpsol("fatrop")
    print(f"# refinement: ipopt vs fatrop | casadi {ca.CasadiMeta.version()} | fatrop plugin: "
          f"{'available' if has_fatrop else 'NOT available'} | {os.cpu_count()} cores "
          f"| family {tuple(args.family)} | {args.instances} instances/size, seeds from "
          f"{args.seed}")
    if not has_fatrop:
        print("# casadi.has_nlpsol('fatrop') is False: this CasADi build ships no fatrop "
              "plugin; only IPOPT is measured.")
        solvers = [s for s in solvers if not s.startswith("fatrop")]
    print("| n | seed | solver | status | ok | iters | objective | gap % | jerk viol | lin viol "
          "| build s | solve s | total s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    rows: list[Row] = []
    t_start = time.perf_counter()
    family = (args.family[0], args.family[1], args.family[2])
    warm = make_case(family, 50, args.seed)
    for s in solvers:  # untimed: loads the plugins and warms caches
        RUNNERS[s](warm.unit, warm.w0)
    for n in args.sizes:
        for k in range(args.instances):
            case = make_case(family, n, args.seed + k)
            if case.relaxed_violation <= case.problem.jerk_tol:
                print(f"# n={n} seed={case.seed}: relaxation already exact (refinement "
                      "would be skipped by refine='auto')")
            for s in solvers:
                row = check(n, case, RUNNERS[s](case.unit, case.w0))
                rows.append(row)
                print_row(row)
    print_summary(rows, solvers, args.sizes)
    print(f"\n# total wall time {time.perf_counter() - t_start:.1f} s")


if __name__ == "__main__":
    main()

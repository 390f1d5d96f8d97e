"""Refinement step: speedplan's refinement against its previous IPOPT call and plain IPOPT.

What it measures
----------------
When the SOCP relaxation is not exact, ``solve_problem`` refines the relaxed ``w`` on the
original (nonconvex) problem. This script solves that refinement, from the same start and on
the same unit-scaled problem ``solve_problem`` passes, with

``new``
    :func:`speedplan.solve.refine.refine`: the banded interior-point method from three starts,
    the best accepted point; IPOPT only if none is accepted.
``old``
    The previous refinement, ``refine_ipopt`` as of commit ``--old-commit`` (rows divided by
    their bound, adaptive barrier update, ``tol = 1e-10``), loaded from git; skipped when git
    or the commit is unavailable.
``plain``
    CasADi + IPOPT with its default options on the plain formulation (``Σ τ_i / sqrt(w_i)``,
    rows ``(c · w) sqrt(w_i) ∈ [-B_i, B_i]``), written here independently of speedplan.
``plain-tight``
    The same with ``tol = constr_viol_tol = 1e-10``: IPOPT's defaults stop while rows are
    still violated by up to 90 % of speedplan's tolerance, which buys travel time that no
    exactly feasible point has (below the certified lower bound on some instances).
``plain-1e-12``
    The same with ``tol = constr_viol_tol = 1e-12``. With lateral-jerk rows ``plain-tight``
    still gains up to 1.4e-5 of travel time from rows violated by about 1 % of ``jerk_tol``
    (in problem units; the rows are met to 1e-10 in the unit scaling IPOPT sees); this one
    comes within 1.4e-7 of ``new`` there (``docs/performance.md``).
``ipopt``
    speedplan's IPOPT fallback (:func:`speedplan.solve.ipopt_.refine_ipopt`), alone.
``fatrop``
    CasADi's structure-exploiting ``fatrop`` on a stage-wise rewrite (state
    ``(w_{k-1}, w_k)``, control ``w_{k+1}``); problems without lateral-jerk rows only.
``near``, ``ipopt-default``, ``nearer``
    One run of the banded interior-point method from that start
    (:data:`speedplan.solve.banded_nlp.STARTS`); the summary then also counts the instances
    where the first two agree to :data:`speedplan.solve.refine.AGREE` (``refine`` skips the
    third there).

Every answer is checked with ``solve_problem``'s acceptance test on the original problem
(clipped into ``[0, w_max]``, linear rows within ``1e-7 max(1, max w_max)``, jerk rows within
``jerk_tol``); ``obj`` is then its travel time, else ``FAIL``. ``gap`` is
``obj / lower_bound - 1`` with the relaxation's certified lower bound.

*At equal feasibility.* IPOPT's points violate rows by up to its ``constr_viol_tol`` (and
its bounds by ``bound_relax_factor``), and near a standstill that buys travel time no
feasible point has; ``new``'s rows hold exactly. The last column and the summary therefore
also compare ``new`` with plain-tight's objective at the point it returned (not clipped)
plus the first-order price of its violations, ``Σ |λ_i| violation_i`` with IPOPT's own
multipliers (``tests/oracles.py``, ``ipopt_plain``).

Instances
---------
``benchmarks/data/refine_corpus.npz`` (``plan()`` problems with a braking start whose
relaxation is not exact, built by ``benchmarks/refine_corpus.py``, relaxed start stored) and
:func:`speedplan.solve.paper.paper_instance` draws (``--families``, ``--sizes``, ``--seeds``),
relaxed here with ``solve_discrete(..., refine="never")``; exact ones are skipped.

Timing
------
Each repetition runs every solver on every instance, interleaved (``--repeats``); times are
medians over repetitions, objectives those of the first.

Usage::

    python benchmarks/bench_refine.py --repeats 3
    python benchmarks/refine_corpus.py --seed 2 --draws 800 --max-keep 40 --out /tmp/c2.npz
    python benchmarks/bench_refine.py --corpus benchmarks/data/refine_corpus.npz /tmp/c2.npz
    python benchmarks/bench_refine.py --solvers new plain --sizes 200 --seeds 0 1 --no-corpus
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
import types
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np

from speedplan import solve_discrete
from speedplan.core.checks import FloatArray
from speedplan.core.errors import SolverError, SpeedplanWarning
from speedplan.solve import banded_nlp
from speedplan.solve.discrete import _linear_tol  # speedplan's own acceptance tolerance
from speedplan.solve.ipopt_ import refine_ipopt
from speedplan.solve.paper import paper_instance
from speedplan.solve.problem import DiscreteProblem, StencilRows
from speedplan.solve.refine import AGREE, refine

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from oracles import interior_bounds, ipopt_plain  # the tests' independent IPOPT formulation

CORPUS = Path(__file__).parent / "data" / "refine_corpus.npz"
STARTS = {start.name: start for start in banded_nlp.STARTS}
SOLVERS = ("old", "new", "plain", "plain-tight", "plain-1e-12", "ipopt", "fatrop", *STARTS)
TIGHT = {"tol": 1e-10, "constr_viol_tol": 1e-10}
TIGHTER = {"tol": 1e-12, "constr_viol_tol": 1e-12}
#: "Worse at equal feasibility" counts differences above this (relative): the refinement
#: stops at a scaled optimality error of 1e-9 (``banded_nlp.TOL``), which leaves up to 1.6e-8
#: of the objective on lateral-jerk legs (IPOPT started at its point gains that much).
FEASIBLE_MARGIN = 2e-8
FATROP_BOUND_RELAX = 1e-8  # fatrop's fixed bound relaxation (not settable in CasADi)


@dataclass(frozen=True)
class Case:
    """One instance: the original problem, the unit-scaled one refined, the relaxed start."""

    key: str
    problem: DiscreteProblem
    unit: DiscreteProblem
    w_scale: float
    w0: FloatArray  # relaxed w, unit scale
    lower_bound: float


@dataclass(frozen=True)
class Run:
    """One solver's answer (``w`` in unit scale, ``None`` if it raised) and its wall time."""

    status: str
    success: bool
    w: FloatArray | None
    time: float
    #: Plain IPOPT only: the first-order price of its rows' and bounds' violations,
    #: ``Σ |λ_i| max(violation_i, 0)`` with IPOPT's own multipliers, relative to its
    #: objective (``tests/oracles.py``); 0 for a point that meets every row.
    violation_price: float = 0.0


def unit_case(key: str, p: DiscreteProblem, w0_unit: FloatArray, lower_bound: float) -> Case:
    """Scale ``p`` as ``solve_problem`` does (mean step 1, largest bound 1)."""
    w_scale = float(np.max(p.w_max))
    return Case(key, p, p.scaled(float(np.mean(p.h)), w_scale), w_scale,
                np.asarray(w0_unit, dtype=np.float64), lower_bound)


def load_corpus(path: Path, prefix: str = "") -> list[Case]:
    """The stored ``plan()`` problems (see ``refine_corpus.py``)."""
    z = np.load(path)
    cases = []
    for i, label in enumerate(z["labels"]):
        def get(name: str, i: int = i) -> Any:
            return z[f"{i}/{name}"]
        w_min = get("w_min")
        names = [("lat_coef", "lat_bound")] + [(f"lat{j}_coef", f"lat{j}_bound")
                                                for j in range(4)]  # older files: lat_coef
        fams = tuple(StencilRows(coef=get(c), bound=get(b)) for c, b in names
                     if f"{i}/{c}" in z)
        lateral = fams if fams else None
        p = DiscreteProblem(
            s=get("s"), w_max=get("w_max"), accel=get("accel"), decel=get("decel"),
            jerk=get("jerk"), w_start=float(get("ends")[0]), w_end=float(get("ends")[1]),
            w_min=w_min if w_min.any() else None, lateral=lateral,
        )
        cases.append(unit_case(f"{prefix}plan{i} {label}", p, get("w0"),
                               float(get("lower_bound"))))
    return cases


def paper_case(family: tuple[str, str, str], n: int, seed: int) -> Case | None:
    """A paper instance relaxed by speedplan; ``None`` if the relaxation is exact."""
    inst = paper_instance(*family, n=n, seed=seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SpeedplanWarning)  # "relaxation not exact": expected
        sol = solve_discrete(inst.w_max, inst.A, inst.J, refine="never")
    if sol.exact:
        return None
    a = np.broadcast_to(inst.A, n - 1).astype(np.float64)
    p = DiscreteProblem(s=np.arange(n, dtype=np.float64), w_max=inst.w_max, accel=a, decel=a,
                        jerk=inst.J)
    w_scale = float(np.max(p.w_max))
    return unit_case(f"paper {'/'.join(family)} n={n} seed={seed}", p,
                     np.asarray(sol.relaxation.w) / w_scale, sol.lower_bound)


def accepted(case: Case, w_unit: FloatArray) -> bool:
    """``solve_problem``'s acceptance test of a refined point."""
    p = case.problem
    w = np.clip(w_unit * case.w_scale, 0.0, p.w_max)
    return bool(p.linear_violation(w) <= _linear_tol(p) and p.jerk_violation(w) <= p.jerk_tol)


def evaluate(case: Case, run: Run) -> dict[str, float | bool]:
    """Objective, gap and jerk violation (in units of ``jerk_tol``) of an accepted run."""
    p = case.problem
    if run.w is None or not np.all(np.isfinite(run.w)):
        return {"ok": False, "obj": float("nan"), "gap": float("nan"), "viol": float("nan")}
    w = np.clip(run.w * case.w_scale, 0.0, p.w_max)
    ok = run.success and accepted(case, run.w)
    obj = p.travel_time(w)
    # At equal feasibility: the point as returned (clipping would pay for the bounds' share
    # of the price a second time) plus the price of all its violations.
    feasible = p.travel_time(run.w * case.w_scale) * (1.0 + run.violation_price)
    return {"ok": ok, "obj": obj, "gap": obj / case.lower_bound - 1.0,
            "viol": p.jerk_violation(w) / p.jerk_tol, "obj_feasible": feasible}


# --- solvers ----------------------------------------------------------------------------------


def run_new(case: Case) -> Run:
    t0 = time.perf_counter()
    res = refine(case.unit, case.w0, accept=lambda w: accepted(case, w))
    return Run(res.status, res.success, res.w, time.perf_counter() - t0)


def run_start(case: Case, name: str) -> Run:
    """One run of the banded interior-point method from one of its starts."""
    t0 = time.perf_counter()
    res = banded_nlp.solve_banded_nlp(case.unit, case.w0, STARTS[name])
    return Run(res.status, res.success, res.w, time.perf_counter() - t0)


def run_refine_ipopt(fn: Callable[[DiscreteProblem, FloatArray], Any], case: Case) -> Run:
    """A ``refine_ipopt``-like function (this one or an earlier one) on ``case``, timed."""
    t0 = time.perf_counter()
    try:
        res = fn(case.unit, case.w0)
    except SolverError as exc:
        return Run(f"error: {exc}", False, None, time.perf_counter() - t0)
    return Run(res.status, res.success, res.w, time.perf_counter() - t0)


def load_old(commit: str) -> Callable[[Case], Run] | None:
    """``refine_ipopt`` as of ``commit``, executed inside the current ``speedplan.solve``."""
    root = Path(__file__).resolve().parents[1]
    try:
        src = subprocess.run(
            ["git", "-C", str(root), "show", f"{commit}:speedplan/solve/ipopt_.py"],
            check=True, capture_output=True, text=True,
        ).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    module = types.ModuleType("speedplan.solve._ipopt_old")
    module.__package__ = "speedplan.solve"
    sys.modules[module.__name__] = module  # dataclasses look their module up
    exec(compile(src, f"{commit}:speedplan/solve/ipopt_.py", "exec"), module.__dict__)
    old_refine = module.refine_ipopt
    return lambda case: run_refine_ipopt(old_refine, case)


def run_plain(case: Case, options: dict[str, Any] | None = None) -> Run:
    """CasADi + IPOPT, default options unless given, on the plain formulation.

    The formulation and the first-order price of its violations are the test suite's
    independent oracle (``tests/oracles.py``, :func:`ipopt_plain`).
    """
    t0 = time.perf_counter()
    ans = ipopt_plain(case.unit, case.w0, options)
    return Run(ans.status, ans.success, ans.w, time.perf_counter() - t0, ans.violation_price)


def run_fatrop(case: Case) -> Run:
    """fatrop on the lifted form: stage ``k`` has state ``(w_{k-1}, w_k)``, control ``w_{k+1}``.

    Per stage: two gap-closing rows, the acceleration row and the jerk row ``w''_k sqrt(w_k)``
    (bounds ``±J_k``); fatrop relaxes every bound by 1e-8, undone here before the call.
    """
    p = case.unit
    if p.lateral is not None or not np.isfinite(p.jerk).all():
        return Run("skipped (lateral or absent rows)", False, None, 0.0)
    t0 = time.perf_counter()
    m = p.n - 2
    v = ca.SX.sym("v", 3 * m + 2)
    z = ca.reshape(v[: 3 * m], 3, m)  # column k-1 = (w_{k-1}, w_k, w_{k+1}) of stage k
    last = v[3 * m:]
    prev, cur, nxt = z[0, :], z[1, :], z[2, :]
    c = p.second_difference_weights
    wpp = ca.DM(c[:, 0]).T * prev + ca.DM(c[:, 1]).T * cur + ca.DM(c[:, 2]).T * nxt
    g = ca.vertcat(ca.vec(ca.vertcat(ca.horzcat(z[0:2, 1:], last) - ca.vertcat(cur, nxt),
                                     cur - prev, wpp * ca.sqrt(cur))), last[1] - last[0])
    zeros = np.zeros(m)
    lo_a, hi_a = -p.decel * p.h, p.accel * p.h
    lbg = np.concatenate((np.column_stack((zeros, zeros, lo_a[:m], -p.jerk)).ravel(), lo_a[m:]))
    ubg = np.concatenate((np.column_stack((zeros, zeros, hi_a[:m], p.jerk)).ravel(), hi_a[m:]))
    lb, ub = interior_bounds(p)
    inf = np.full(m, np.inf)
    lbx = np.concatenate((np.column_stack((-inf, lb[1:-1], -inf)).ravel(), [-np.inf, p.w_end]))
    ubx = np.concatenate((np.column_stack((inf, ub[1:-1], inf)).ravel(), [np.inf, p.w_end]))
    lbx[0] = ubx[0] = p.w_start
    w = np.clip(case.w0, lb, ub)
    w[0], w[-1] = p.w_start, p.w_end
    x0 = np.concatenate((np.column_stack((w[:-2], w[1:-1], w[2:])).ravel(), w[-2:]))
    try:
        solver = ca.nlpsol("refine_fatrop", "fatrop",
                           {"x": v, "f": ca.dot(ca.DM(p.tau), ca.vec(1.0 / ca.sqrt(cur))), "g": g},
                           {"structure_detection": "auto", "print_time": False,
                            "equality": [True, True, False, False] * m + [False],
                            "fatrop": {"print_level": 0, "tolerance": 1e-10,
                                       "constr_viol_tol": 1e-10}})
        tight = [np.where(np.isfinite(b) & (lbx < ubx), b + sgn * FATROP_BOUND_RELAX
                          * np.maximum(1.0, np.abs(b)), b)
                 for b, sgn in ((lbx, 1.0), (ubx, -1.0))]
        tight_g = [np.where(np.isfinite(b) & (lbg < ubg), b + sgn * FATROP_BOUND_RELAX
                            * np.maximum(1.0, np.abs(b)), b)
                   for b, sgn in ((lbg, 1.0), (ubg, -1.0))]
        sol = solver(x0=x0, lbx=tight[0], ubx=tight[1], lbg=tight_g[0], ubg=tight_g[1])
    except RuntimeError as exc:
        return Run(f"error: {str(exc).strip().splitlines()[-1]}", False, None,
                   time.perf_counter() - t0)
    xv = np.asarray(sol["x"]).ravel()
    w_out = np.concatenate(([p.w_start], xv[1 : 3 * m : 3], [p.w_end]))
    return Run("fatrop", bool(solver.stats().get("success", False)), w_out,
               time.perf_counter() - t0)


# --- report -----------------------------------------------------------------------------------


def fmt(value: float, ok: bool) -> str:
    return f"{value:.8g}" if ok else "FAIL"


def main(argv: list[str] | None = None) -> None:
    """Run every solver on every instance, interleaved, and print the tables."""
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--corpus", nargs="+", default=[str(CORPUS)],
                    help="corpus files from refine_corpus.py")
    ap.add_argument("--no-corpus", action="store_true")
    ap.add_argument("--families", nargs="+", default=["rnd/cnst/logrnd", "pw lin/rnd/logrnd",
                                                      "rnd/cnst/rnd"])
    ap.add_argument("--sizes", type=int, nargs="+", default=[1000, 4000])
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument("--solvers", nargs="+", choices=SOLVERS,
                    default=["old", "new", "plain", "plain-tight"])
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--old-commit", default="2c8fb92")
    args = ap.parse_args(argv)

    runners: dict[str, Callable[[Case], Run]] = {
        "new": run_new, "plain": run_plain, "fatrop": run_fatrop,
        "ipopt": lambda case: run_refine_ipopt(refine_ipopt, case),
        "plain-tight": lambda case: run_plain(case, TIGHT),
        "plain-1e-12": lambda case: run_plain(case, TIGHTER),
    }
    for name in STARTS:
        runners[name] = lambda case, name=name: run_start(case, name)
    solvers = list(args.solvers)
    if "old" in solvers:
        old = load_old(args.old_commit)
        if old is None:
            print(f"# old: commit {args.old_commit} not available through git; skipped")
            solvers.remove("old")
        else:
            runners["old"] = old
    cases = [] if args.no_corpus else [
        c for k, path in enumerate(args.corpus)
        for c in load_corpus(Path(path), prefix="" if len(args.corpus) == 1 else f"c{k}-")
    ]
    for fam in args.families:
        family = tuple(fam.split("/"))
        assert len(family) == 3, f"family must be W/A/J, got {fam}"
        for n in args.sizes:
            for seed in args.seeds:
                c = paper_case((family[0], family[1], family[2]), n, seed)
                if c is not None:
                    cases.append(c)
    print(f"# refinement benchmark | casadi {ca.CasadiMeta.version()} | {os.cpu_count()} cores "
          f"| {len(cases)} instances | solvers {solvers} | {args.repeats} repeat(s), "
          "interleaved; times are medians [s]")
    t_start = time.perf_counter()
    results: dict[tuple[str, str], dict[str, Any]] = {}
    times: dict[tuple[str, str], list[float]] = {}
    for rep in range(args.repeats):
        for case in cases:
            for s in solvers:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    run = runners[s](case)
                times.setdefault((case.key, s), []).append(run.time)
                if rep == 0:
                    results[(case.key, s)] = {**evaluate(case, run), "status": run.status}

    cols = [s for s in SOLVERS if s in solvers]
    print("\n| instance | n | " + " | ".join(f"{s} t" for s in cols) + " | "
          + " | ".join(f"{s} obj" for s in cols)
          + " | plain viol/tol | lower bound | new gap | new vs plain-tight "
          "| new vs plain-tight at equal feasibility |")
    print("|" + "---|" * (2 * len(cols) + 7))
    for case in cases:
        r = {s: results[(case.key, s)] for s in cols}
        t = {s: statistics.median(times[(case.key, s)]) for s in cols}
        rel = rel_feasible = "-"
        if "new" in r and "plain-tight" in r and r["new"]["ok"] and r["plain-tight"]["ok"]:
            rel = f"{r['new']['obj'] / r['plain-tight']['obj'] - 1:+.1e}"
            rel_feasible = f"{r['new']['obj'] / r['plain-tight']['obj_feasible'] - 1:+.1e}"
        viol = f"{r['plain']['viol']:.2f}" if "plain" in r else "-"
        gap = f"{r['new']['gap']:.2e}" if "new" in r and r["new"]["ok"] else "-"
        print(f"| {case.key} | {case.problem.n} | "
              + " | ".join(f"{t[s]:.3f}" for s in cols) + " | "
              + " | ".join(fmt(float(r[s]["obj"]), bool(r[s]["ok"])) for s in cols)
              + f" | {viol} | {case.lower_bound:.8g} | {gap} | {rel} | {rel_feasible} |",
              flush=True)

    print("\n## Summary")
    print("| solver | accepted | median t [s] | worst t [s] | worse than plain-tight by > 1e-6 "
          "| worst relative to plain-tight | worse than plain-tight at equal feasibility by "
          f"> {FEASIBLE_MARGIN:g} | worst relative to it | below the lower bound |")
    print("|---|---|---|---|---|---|---|---|---|")
    for s in cols:
        rs = [results[(c.key, s)] for c in cases]
        ts = [statistics.median(times[(c.key, s)]) for c in cases]
        both = [(results[(c.key, s)], results[(c.key, "plain-tight")]) for c in cases
                if "plain-tight" in cols and results[(c.key, s)]["ok"]
                and results[(c.key, "plain-tight")]["ok"]]
        rels = [r["obj"] / tight["obj"] - 1 for r, tight in both]
        rels_f = [r["obj"] / tight["obj_feasible"] - 1 for r, tight in both]
        below = sum(bool(r["ok"]) and float(r["gap"]) < 0 for r in rs)
        print(f"| {s} | {sum(bool(r['ok']) for r in rs)}/{len(rs)} | {statistics.median(ts):.3f} "
              f"| {max(ts):.3f} | {sum(x > 1e-6 for x in rels)} "
              f"| {f'{max(rels):+.1e}' if rels else '-'} "
              f"| {sum(x > FEASIBLE_MARGIN for x in rels_f)} "
              f"| {f'{max(rels_f):+.1e}' if rels_f else '-'} | {below} |")
    names = list(STARTS)
    if all(name in cols for name in names):
        first, second = names[0], names[1]
        agree = sum(
            bool(results[(c.key, first)]["ok"] and results[(c.key, second)]["ok"]
                 and abs(results[(c.key, first)]["obj"] - results[(c.key, second)]["obj"])
                 <= AGREE * results[(c.key, first)]["obj"])
            for c in cases)
        print(f"\n{first} and {second} agree to {AGREE:g} on {agree}/{len(cases)} instances")
    if "new" in cols:
        viols = [float(results[(c.key, "new")]["viol"]) for c in cases
                 if results[(c.key, "new")]["ok"]]
        print(f"new: largest jerk-row violation of an accepted point {max(viols):.2e} jerk_tol")
    if "old" in cols and "new" in cols:
        both = [c for c in cases if results[(c.key, "old")]["ok"] and results[(c.key, "new")]["ok"]]
        ratio = [statistics.median(times[(c.key, "old")]) / statistics.median(times[(c.key, "new")])
                 for c in both]
        if ratio:
            print(f"\nold/new time on the {len(both)} instances both solved: median "
                  f"{statistics.median(ratio):.1f}x, min {min(ratio):.1f}x, max {max(ratio):.1f}x")
    print(f"\n# total wall time {time.perf_counter() - t_start:.0f} s")


if __name__ == "__main__":
    main()

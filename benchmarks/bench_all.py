"""Every performance figure in one run: where ``plan()``'s time goes, and more.

Usage::

    python benchmarks/bench_all.py                  # everything (about 4-6 minutes)
    python benchmarks/bench_all.py --quick          # fewer repeats, no 100 k-node runs

Prints, in order:

1. ``plan()`` split into stages, per sample path (``paths/*.json|csv``, LGV limits
   v_max=2, a_max=1, a_lat_max=1, j_max=0.5; road limits for ``road_*``), for a
   deterministic 20-waypoint, 127 m serpentine route (:func:`serpentine`), and for the
   first request of the refinement corpus (a vehicle that starts braking on an 8 m line;
   its relaxation is exact now that standstills are smooth, so ``refine`` stays 0 here: the
   refinement is timed on the stored inexact problems in section 7).
   Stages (medians over ``--repeats``, one warm-up call excluded): model/grid build
   (``build_model``, and grid refinement rounds), relaxation (``solution.relaxation.time``),
   refinement (``solution.refinement.time``), the rest of the solve (scaling, certificate),
   time law (``law_for``), the per-leg checks that decide grid refinement (``check_leg``),
   the final ``verify()``, what is left (``other``), the total, and then ``sample(0.01)``.
   The stages are timed by wrapping those functions inside the real ``plan()`` (exclusive
   times: a wrapped call inside another one counts for its own stage only).
2. ``plan(n=1000)`` against the bare relaxation solve of the same grid
   (``solve_problem(problem, refine="never", backend="auto")``), and
   ``profile_from_waypoints`` on the route.
3. ``plan(j_max=inf)`` against TOPP-RA's ``compute_trajectory`` (toppra, 1-DOF path ``q = s``
   with the same speed bound per node and the same grid: the same discrete problem) and
   copp-py's TOPP2-RA (``copp2_time``), ours and copp's alternating over ``--rounds``;
   *bound*: one evaluation of the curvature and the speed bound at the 8 points per cell of
   the plan's grid (`cell_points`), which every plan needs for its node bounds and its check.
   With ``--baseline TREE`` also the speedplan in TREE (a worker process), alternating.
4. copp-py's jerk-limited TOPP3 (``topp3_socp``) on the same grids, when it is installed.
5. ``import speedplan`` (subprocess, median of ``--import-runs``) and the first ``plan()`` in
   a fresh process: installed from a wheel built here (its kernels compiled by the build),
   and with an empty numba cache (``NUMBA_CACHE_DIR`` in a temporary directory: the first
   use of a wheel built elsewhere).
6. ``solve_discrete`` at 10 k and 100 k nodes: tracemalloc peak per node and the time ratio,
   sizes interleaved, split into iterations and time per node and iteration
   (``bench_kernel_scaling.py``; ``--seeds`` for more random draws).
7. The refinement (``speedplan.solve.refine.refine``) on the stored corpus of inexact
   ``plan()`` relaxations (``benchmarks/data/refine_corpus.npz``, see ``bench_refine.py``).
"""

from __future__ import annotations

import argparse
import importlib
import math
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from collections import defaultdict
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path as FsPath
from typing import Any

import numpy as np

import speedplan as sp
from speedplan.geometry import Line
from speedplan.io import read_path, read_zones
from speedplan.model import Leg, PlanRequest, build_model
from speedplan.solve.banded import compile_kernel
from speedplan.solve.discrete import solve_problem
from speedplan.timing import SpeedProfile

ROOT = FsPath(__file__).resolve().parents[1]
LGV = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)
ROAD = sp.Limits(v_max=15.0, a_max=2.0, a_lat_max=3.0, j_max=1.0)
# The first case of benchmarks/refine_corpus.py: a vehicle that starts braking (inexact when
# the corpus was built; exact with the current model).
ISSUE_LIMITS = sp.Limits(v_max=1.5103489923280469, a_max=0.8675731399347792, a_lat_max=1,
                         j_max=0.1324661827707745)
ISSUE_KW: dict[str, Any] = {"v0": 0.09343837197243295, "a0": -0.15353125453853034}
ISSUE_LENGTH = 8.149176458679765

STAGES = ("build", "relax", "refine", "solve rest", "law", "checks", "verify", "other",
          "total")


def serpentine() -> np.ndarray:
    """20 waypoints: ten 10 m aisles 3 m apart, driven alternately (127 m of legs)."""
    pts = []
    for row in range(10):
        xs = (0.0, 10.0) if row % 2 == 0 else (10.0, 0.0)
        pts += [(xs[0], 3.0 * row), (xs[1], 3.0 * row)]
    return np.array(pts)


def cases() -> list[tuple[str, sp.Path, sp.Limits, dict[str, Any]]]:
    out = []
    for f in sorted(p for p in (ROOT / "paths").iterdir() if p.suffix in (".csv", ".json")):
        zones = read_zones(str(f))
        out.append((f.name, read_path(str(f)), ROAD if "road" in f.name else LGV,
                    {"zones": zones} if zones else {}))
    out.append(("serpentine 20 wp", sp.Path.from_waypoints(serpentine()), LGV, {}))
    out.append(("braking start 8 m", sp.Path.from_segments([Line(ISSUE_LENGTH)]), ISSUE_LIMITS,
                ISSUE_KW))
    return out


# --- 1. stages of plan() -------------------------------------------------------------------


@contextmanager
def staged(acc: dict[str, float]) -> Iterator[None]:
    """Wrap the stage functions that ``plan()`` calls; accumulate their times into ``acc``."""
    plan_mod = importlib.import_module("speedplan.strategy")  # the stages it calls
    saved: list[tuple[Any, str, Any]] = []
    inner: list[float] = []  # time spent in wrapped calls nested in the open ones

    def wrap(owner: Any, name: str, stage: str,
             after: Callable[[Any], None] | None = None) -> None:
        real = getattr(owner, name)

        def timed(*args: Any, **kwargs: Any) -> Any:
            inner.append(0.0)
            t0 = time.perf_counter()
            try:
                out = real(*args, **kwargs)
            finally:
                elapsed = time.perf_counter() - t0
                nested = inner.pop()
                acc[stage] += elapsed - nested  # exclusive: nested stages count as theirs
                if inner:
                    inner[-1] += elapsed
            if after is not None:
                after(out)
            return out

        saved.append((owner, name, real))
        setattr(owner, name, timed)

    def split(sol: Any) -> None:
        relax = sol.relaxation.time if sol.relaxation is not None else 0.0
        refine = sol.refinement.time if sol.refinement is not None else 0.0
        acc["relax"] += relax
        acc["refine"] += refine
        acc["solve rest"] -= relax + refine

    wrap(plan_mod, "build_model", "build")
    wrap(plan_mod, "leg_on_grid", "build")
    wrap(plan_mod, "refined_grid", "build")
    wrap(plan_mod, "solve_problem", "solve rest", split)
    wrap(plan_mod, "law_for", "law")
    wrap(SpeedProfile, "check_leg", "checks")
    wrap(SpeedProfile, "verify", "verify")
    try:
        yield
    finally:
        for owner, name, real in reversed(saved):
            setattr(owner, name, real)


def plan_stages(path: sp.Path, lim: sp.Limits, kw: dict[str, Any],
                repeats: int) -> tuple[dict[str, float], Any]:
    runs: list[dict[str, float]] = []
    prof = None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sp.plan(path, lim, **kw)  # warm-up
        for _ in range(repeats):
            acc: dict[str, float] = defaultdict(float)
            with staged(acc):
                t0 = time.perf_counter()
                prof = sp.plan(path, lim, **kw)
                acc["total"] = time.perf_counter() - t0
            acc["other"] = acc["total"] - sum(acc[k] for k in STAGES[:-2])
            runs.append(acc)
    return {k: statistics.median(r[k] for r in runs) for k in STAGES}, prof


def median_time(call: Callable[[], Any], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        call()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def section_stages(repeats: int) -> None:
    print("\n== 1. plan() by stage [ms], medians of", repeats, "==")
    head = " ".join(f"{k:>10}" for k in STAGES)
    print(f"{'case':<22} {'n':>5} {'T [s]':>8} {head} {'sample':>8}")
    for name, path, lim, kw in cases():
        st, prof = plan_stages(path, lim, kw, repeats)
        t_sample = median_time(lambda pr=prof: pr.sample(0.01), repeats)
        n = sum(leg.s.size for leg in prof.legs)
        cols = " ".join(f"{1e3 * st[k]:>10.2f}" for k in STAGES)
        print(f"{name:<22} {n:>5} {prof.duration:>8.3f} {cols} {1e3 * t_sample:>8.2f}")


# --- 2. plan() against its bare relaxation, profile_from_waypoints ---------------------------


def section_overhead(repeats: int) -> None:
    print(f"\n== 2. plan(n=1000) against the bare relaxation of its grid, medians of {repeats} ==")
    print(f"{'case':<22} {'plan [ms]':>10} {'relax [ms]':>11} {'ratio':>7}")
    for name, path, lim, kw in cases()[:-1]:
        kw = {**kw, "n": 1000}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sp.plan(path, lim, **kw)
            t_plan = median_time(lambda p=path, li=lim, k=kw: sp.plan(p, li, **k), repeats)
            problems = [leg.problem for leg in build_model(PlanRequest.create(path, lim, **kw)).legs
                        if isinstance(leg, Leg)]
            t_relax = median_time(
                lambda ps=problems: [solve_problem(p, refine="never", backend="auto")
                                     for p in ps], repeats)
        print(f"{name:<22} {1e3 * t_plan:>10.2f} {1e3 * t_relax:>11.2f} {t_plan / t_relax:>7.2f}")
    wps = serpentine()
    kwargs = {"v_max": 2.0, "a_max": 1.0, "a_lat_max": 1.0, "j_max": 0.5}
    for n in (None, 1000):
        extra = {} if n is None else {"n": n}
        sp.profile_from_waypoints(wps, **kwargs, **extra)
        t = median_time(lambda e=extra: sp.profile_from_waypoints(wps, **kwargs, **e), repeats)
        print(f"profile_from_waypoints(20 waypoints, dt=0.01, n={n}): {1e3 * t:.2f} ms")


# --- 3. no jerk limit: TOPP-RA ------------------------------------------------------------


def toppra_time(s: np.ndarray, w_max: np.ndarray, a_max: float,
                repeats: int) -> tuple[float, float]:
    import toppra as ta
    import toppra.algorithm as algo
    import toppra.constraint as constraint

    ta.setup_logging("WARNING")
    v = np.sqrt(w_max)

    def run() -> Any:
        path = ta.SplineInterpolator(np.array([s[0], s[-1]]), np.array([[s[0]], [s[-1]]]))
        vel = constraint.JointVelocityConstraintVarying(
            lambda x: np.array([[-np.interp(x, s, v), np.interp(x, s, v)]]))
        acc = constraint.JointAccelerationConstraint(np.array([[-a_max, a_max]]))
        inst = algo.TOPPRA([vel, acc], path, gridpoints=s, parametrizer="ParametrizeConstAccel")
        return inst.compute_trajectory(0, 0)

    traj = run()
    return median_time(run, repeats), float(traj.duration)


def plan_and_problem(path: sp.Path, lim: sp.Limits, kw: dict[str, Any],
                     repeats: int) -> tuple[Any, float, Any]:
    """``plan()``'s profile, its median time, and the discrete problem of its single leg.

    The problem is ``None`` when the request has several legs (cusps, stops).
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        prof = sp.plan(path, lim, **kw)
        t_ours = median_time(lambda: sp.plan(path, lim, **kw), repeats)
        legs = [leg for leg in build_model(PlanRequest.create(path, lim, **kw)).legs
                if isinstance(leg, Leg)]
    single = len(legs) == 1 and len(prof.legs) == 1
    return prof, t_ours, legs[0].problem if single else None


def copp2_time(s: np.ndarray, w_max: np.ndarray, lim: sp.Limits,
               repeats: int) -> tuple[float, float]:
    """copp-py's TOPP2-RA, the whole call (constraints, reachability pass, time integration).

    1-DOF path ``q = s`` on the grid ``s`` with the speed bound ``sqrt(w_max)`` per node,
    ``a_max`` and ``a_decel``, rest to rest: the same discrete problem as ``plan(j_max=inf)``
    solves. Returns the median time and copp's duration (``s_to_t_topp2``).
    """
    import copp_py as copp

    n = s.size
    v = np.maximum(np.sqrt(w_max), 1e-9)[:, None]

    def run() -> float:
        robot = copp.Robot(1)
        robot.append_s(s)
        robot.set_q(s[:, None], np.ones((n, 1)), np.zeros((n, 1)), 0)
        robot.add_velocity_limits(v, -v, start_idx_s=0, length=n)
        robot.add_acceleration_limits(np.array([lim.a_max]), np.array([-lim.a_decel]),
                                      start_idx_s=0, length=n)
        problem = copp.solver.topp2_ra.Problem(robot.constraints, idx_s_interval=(0, n - 1),
                                               a_boundary=(0.0, 0.0))
        a = copp.solver.topp2_ra.solve(problem)
        return float(copp.interpolation.s_to_t_topp2(s, np.asarray(a))[0])

    duration = run()
    return median_time(run, repeats), duration


def nojerk_cases() -> list[tuple[str, sp.Path, sp.Limits, dict[str, Any]]]:
    """Section 3's cases: those of `cases` but the braking start, without a jerk limit."""
    return [(name, path, sp.Limits(v_max=lim.v_max, a_max=lim.a_max, a_lat_max=lim.a_lat_max,
                                   j_max=math.inf), kw)
            for name, path, lim, kw in cases()[:-1]]


class Baseline:
    """``plan(j_max=inf)`` timed in a worker process that imports speedplan from ``tree``.

    The worker is this script (``--nojerk-worker``) with ``PYTHONPATH=tree``: it answers a
    line ``case repeats`` with the median time of that many calls of section 3's case and its
    duration, so that section 3 times the two versions alternately, in one run.
    """

    def __init__(self, tree: str) -> None:
        env = {**os.environ, "PYTHONPATH": os.path.abspath(tree)}
        self.proc = subprocess.Popen([sys.executable, __file__, "--nojerk-worker"], env=env,
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        self.where = self._ask("where")

    def _ask(self, line: str) -> str:
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self.proc.stdin.write(line + "\n")
        self.proc.stdin.flush()
        return self.proc.stdout.readline().strip()

    def time(self, case: int, repeats: int) -> tuple[float, float]:
        """Median time [s] of ``repeats`` plans of case ``case``, and the plan's duration."""
        t, duration = self._ask(f"{case} {repeats}").split()
        return float(t), float(duration)

    def close(self) -> None:
        self._ask("quit")
        self.proc.wait()


def nojerk_worker() -> None:
    """The loop of `Baseline`'s worker process."""
    work = nojerk_cases()
    for line in sys.stdin:
        if line.strip() == "where":
            print(os.path.dirname(sp.__file__), flush=True)
            continue
        if line.strip() == "quit":
            print("bye", flush=True)
            return
        case, repeats = (int(x) for x in line.split())
        _, path, lim, kw = work[case]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            duration = sp.plan(path, lim, **kw).duration
            t = median_time(lambda p=path, li=lim, k=kw: sp.plan(p, li, **k), repeats)
        print(f"{t!r} {duration!r}", flush=True)


def bound_time(path: sp.Path, lim: sp.Limits, kw: dict[str, Any], s: np.ndarray,
               repeats: int) -> float:
    """One evaluation of the curvature and the speed bound at the `cell_points` of ``s``.

    What every no-jerk plan computes at least once on its final grid: its node bounds and
    its check both need them.
    """
    from speedplan.core.numerics import cell_points
    from speedplan.geometry import SpeedBound

    points = cell_points(s)
    return median_time(lambda: SpeedBound(path, lim, kw.get("zones")).evaluate(points), repeats)


def section_toppra(repeats: int, rounds: int = 1, baseline: str | None = None) -> None:
    print(f"\n== 3. plan(j_max=inf) against TOPP-RA compute_trajectory and copp-py TOPP2-RA "
          f"(whole calls), medians of {repeats} calls, then of {rounds} alternating rounds ==")
    try:
        import copp_py  # noqa: F401
        have_copp = True
    except ImportError:
        have_copp = False
        print("copp-py is not installed (pip install copp-py, or the bench extra): its "
              "columns are skipped")
    before = Baseline(baseline) if baseline else None
    if before is not None:
        print(f"before: speedplan from {before.where}")
    print(f"{'case':<22} {'n':>5} {'ours [ms]':>10}"
          + (f" {'before [ms]':>11} {'speed-up':>8}" if before else "")
          + f" {'bound [ms]':>10} {'toppra [ms]':>12} {'ratio':>7}"
          f" {'copp2 [ms]':>11} {'ratio':>7} {'T ours':>9}"
          + (f" {'T before':>9}" if before else "") + f" {'T toppra':>9} {'T copp2':>9}")
    for i, (name, path, nojerk, kw) in enumerate(nojerk_cases()):
        prof, _, p = plan_and_problem(path, nojerk, kw, 1)
        if p is None:
            print(f"{name:<22} skipped: several legs")
            continue
        ours, old, copp = [], [], []
        dur_old = dur_c2 = math.nan
        for _ in range(rounds):  # the versions alternate: the load they see is alike
            ours.append(plan_and_problem(path, nojerk, kw, repeats)[1])
            if before is not None:
                t_old, dur_old = before.time(i, repeats)
                old.append(t_old)
            if have_copp:
                t_c2, dur_c2 = copp2_time(p.s, p.w_max, nojerk, repeats)
                copp.append(t_c2)
        t_ours = statistics.median(ours)
        t_c2 = statistics.median(copp) if copp else math.nan
        t_bound = bound_time(path, nojerk, kw, p.s, repeats)
        t_ta, dur_ta = toppra_time(p.s, p.w_max, nojerk.a_max, repeats)
        line = f"{name:<22} {p.n:>5} {1e3 * t_ours:>10.2f}"
        if before is not None:
            t_old = statistics.median(old)
            line += f" {1e3 * t_old:>11.2f} {t_old / t_ours:>8.2f}"
        line += (f" {1e3 * t_bound:>10.2f} {1e3 * t_ta:>12.2f} {t_ta / t_ours:>7.1f}"
                 f" {1e3 * t_c2:>11.2f} {t_c2 / t_ours:>7.2f} {prof.duration:>9.3f}")
        if before is not None:
            line += f" {dur_old:>9.3f}"
        print(line + f" {dur_ta:>9.3f} {dur_c2:>9.3f}")
    if before is not None:
        before.close()


# --- 4. copp-py ------------------------------------------------------------------------------


def copp_solve(p: Any, lim: sp.Limits) -> tuple[float, np.ndarray]:
    """copp-py's TOPP3-SOCP on the grid ``p.s`` (1-DOF path ``q = s``): duration and ``a``.

    Same speed bound per node (``sqrt(p.w_max)``, lateral limit included), ``a_max``,
    ``a_decel`` and ``j_max`` on ``d³s/dt³``, rest to rest. copp linearises its jerk rows
    around a reference profile (here ``p.w_max``) and has its own discretisation of the jerk
    (``b = s''`` as a node variable) and time integration (``s_to_t_topp3``): not our
    discrete problem, so the durations differ by the models, not only by the solvers.
    """
    import copp_py as copp

    s, n = p.s, p.n
    robot = copp.Robot(1)
    robot.append_s(s)
    robot.set_q(s[:, None], np.ones((n, 1)), np.zeros((n, 1)), 0, dddq=np.zeros((n, 1)))
    v = np.maximum(np.sqrt(p.w_max), 1e-9)[:, None]  # copp wants strictly signed limits
    robot.add_velocity_limits(v, -v, start_idx_s=0, length=n)
    robot.add_acceleration_limits(np.array([lim.a_max]), np.array([-lim.a_decel]),
                                  start_idx_s=0, length=n)
    robot.add_jerk_limits(np.array([lim.j_max]), np.array([-lim.j_max]), start_idx_s=0,
                          length=n)
    problem = copp.solver.topp3_socp.Problem(robot.constraints, p.w_max.copy(), idx_s_start=0)
    prof = copp.solver.topp3_socp.solve(problem)
    duration, _ = copp.interpolation.s_to_t_topp3(s, prof)
    return float(duration), np.asarray(prof.a, dtype=np.float64)


def section_copp(repeats: int) -> None:
    print(f"\n== 4. copp-py topp3_socp (jerk-limited), same grid and speed bound, medians of "
          f"{repeats} ==")
    try:
        import copp_py
    except ImportError:
        print("copp-py is not installed (pip install copp-py, or the bench extra): skipped")
        return
    print(f"copp-py {copp_py.__version__}. T ours: plan()'s continuous law (and our discrete "
          "objective); T copp: copp's s_to_t_topp3; viol: copp's a against our jerk rows "
          "(in units of jerk_tol)")
    print(f"{'case':<22} {'n':>5} {'ours [ms]':>10} {'copp [ms]':>10} {'ratio':>6} {'T ours':>9}"
          f" {'(discrete)':>10} {'T copp':>9} {'viol':>8}")
    for name, path, lim, kw in cases()[:-1]:
        prof, t_ours, p = plan_and_problem(path, lim, kw, repeats)
        if p is None:
            print(f"{name:<22} skipped: several legs")
            continue
        try:
            dur, a = copp_solve(p, lim)
            t_copp = median_time(lambda pp=p, li=lim: copp_solve(pp, li), repeats)
        except Exception as exc:  # report and go on: copp may refuse a grid
            print(f"{name:<22} copp failed: {type(exc).__name__}: {exc}")
            continue
        viol = p.jerk_violation(np.clip(a, 0.0, p.w_max)) / p.jerk_tol
        print(f"{name:<22} {p.n:>5} {1e3 * t_ours:>10.2f} {1e3 * t_copp:>10.2f}"
              f" {t_copp / t_ours:>6.1f} {prof.duration:>9.3f}"
              f" {prof.legs[0].solution.objective:>10.3f} {dur:>9.3f} {viol:>8.2g}")


# --- 5. import and cold start --------------------------------------------------------------


def _run(code: str, env: dict[str, str], *args: str, cwd: str = str(ROOT)) -> str:
    res = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True,
                         env=env, cwd=cwd, timeout=900)
    if res.returncode != 0:
        raise RuntimeError(res.stderr)
    return res.stdout.strip()


COLD = """
import sys, time
t0 = time.perf_counter()
import speedplan as sp
from speedplan.io import read_path
t1 = time.perf_counter()
path = read_path(sys.argv[2])
lim = sp.Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5)
prof = sp.plan(path, lim)
t2 = time.perf_counter()
first = prof.legs[0].solution.backend
n_plans, banded_at = int(sys.argv[1]), None
for _ in range(n_plans):
    prof = sp.plan(path, lim)
    if banded_at is None and "banded" in prof.solution.backend:
        banded_at = time.perf_counter() - t1
t3 = time.perf_counter()
print(f"{t1 - t0:.3f} {t2 - t1:.3f} {t3 - t2:.3f} {first} "
      f"{'-' if banded_at is None else f'{banded_at:.1f}'}")
"""


def _busy(count: int) -> list[subprocess.Popen[bytes]]:
    """``count`` processes that keep a core busy each (a loaded machine), until killed."""
    return [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(count)]


def _cold_starts(env: dict[str, str], plans: int) -> None:
    print(f"  {'':<44} {'import':>7} {'1st plan':>9} {f'{plans} more':>9} {'backend':>9}"
          f" {'banded after':>13}")
    sample = str(ROOT / "paths" / "u_turn.json")
    with tempfile.TemporaryDirectory() as site:
        sys.path.insert(0, str(FsPath(__file__).parent))
        from bench_first_use import install_wheel

        t_wheel = install_wheel(ROOT, FsPath(site))
        clean = {k: v for k, v in env.items() if k != "NUMBA_CACHE_DIR"}
        # run from elsewhere: from ROOT, `python -c` would import the source tree instead
        installed = [_run(COLD, {**clean, "PYTHONPATH": site}, str(plans), sample,
                          cwd=tempfile.gettempdir()).split() for _ in range(2)]
    with tempfile.TemporaryDirectory() as cache:
        fresh = _run(COLD, {**env, "NUMBA_CACHE_DIR": cache}, str(plans), sample).split()
        _wait_for_cache_locks(cache)  # the background compilation the fresh process started
        warm = _run(COLD, {**env, "NUMBA_CACHE_DIR": cache}, str(plans), sample).split()
    with tempfile.TemporaryDirectory() as cache:
        t0, r0 = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
        families = subprocess.run([sys.executable, "-m", "speedplan", "compile"],
                                  env={**env, "NUMBA_CACHE_DIR": cache}, check=True,
                                  capture_output=True, text=True).stdout
        t_compile = time.perf_counter() - t0
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    for label, out in ((f"installed from a wheel built here ({t_wheel:.1f} s)", installed[0]),
                       ("the same installation, once more", installed[1]),
                       ("empty cache (kernels not compiled yet)", fresh),
                       ("the same cache, filled (warm)", warm)):
        print(f"  {label:<44} {float(out[0]):>7.2f} {float(out[1]):>9.2f}"
              f" {float(out[2]):>9.2f} {out[3]:>9} {out[4] + ('' if out[4] == '-' else ' s'):>13}")
    ratio = (float(fresh[1]) + float(fresh[2])) / (float(warm[1]) + float(warm[2]))
    print(f"  plans with an empty cache / warm: {ratio:.2f}; `speedplan compile` into an "
          f"empty cache: {t_compile:.1f} s ({cpu:.1f} s of CPU, user + sys, every process; "
          f"{'; '.join(families.strip().splitlines())})")


def _wait_for_cache_locks(cache: str) -> None:
    """Wait until no background compilation into ``cache`` holds its lock (cache filled)."""
    from speedplan.core.jit import FAMILIES

    before = os.environ.get("NUMBA_CACHE_DIR")
    os.environ["NUMBA_CACHE_DIR"] = cache  # the locks are per cache directory
    try:
        locks = [family.lock_path() for family in FAMILIES.values()]
    finally:
        if before is None:
            del os.environ["NUMBA_CACHE_DIR"]
        else:
            os.environ["NUMBA_CACHE_DIR"] = before
    deadline = time.time() + 900
    while any(os.path.exists(lock) for lock in locks) and time.time() < deadline:
        time.sleep(0.5)


def section_startup(import_runs: int, plans: int = 200, busy: int = 4) -> None:
    print("\n== 5. import speedplan and the first plan() ==")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        p for p in (str(ROOT), os.environ.get("PYTHONPATH")) if p)}
    code = ("import time; t = time.perf_counter(); import speedplan, sys; "
            "print(time.perf_counter() - t, "
            "' '.join(m for m in ('casadi', 'matplotlib', 'numba') if m in sys.modules))")
    outs = [_run(code, env).split(maxsplit=1) for _ in range(import_runs)]
    times = sorted(float(o[0]) for o in outs)
    loaded = {o[1] if len(o) > 1 else "" for o in outs}
    print(f"import speedplan: median {statistics.median(times):.3f} s over {import_runs} "
          f"subprocesses (min {times[0]:.3f}, max {times[-1]:.3f}); heavy modules loaded: "
          f"{sorted(loaded - {''}) or 'none'}")
    print(f"a new process planning paths/u_turn.json {plans + 1} times [s]; 'banded after': "
          f"when the compiled kernel first answered (from the import's end; '-': never)")
    print(f"- machine as it is (load average {os.getloadavg()[0]:.1f}):")
    _cold_starts(env, plans)
    procs = _busy(busy)
    try:
        time.sleep(2.0)
        print(f"- with {busy} busy processes started here (load average "
              f"{os.getloadavg()[0]:.1f}):")
        _cold_starts(env, plans)
    finally:
        for proc in procs:
            proc.kill()
            proc.wait()


# --- 6. memory and scaling of solve_discrete -----------------------------------------------


def section_memory(sizes: list[int], rounds: int, seeds: list[int]) -> None:
    """As ``bench_kernel_scaling.py``: memory, times and the ratio split into its factors."""
    sys.path.insert(0, str(FsPath(__file__).parent))
    from bench_kernel_scaling import interleaved

    print(f"\n== 6. solve_discrete (paper rnd/cnst/cnst): memory per node, time ratio over "
          f"{rounds} interleaved rounds ==")
    for seed in seeds:
        interleaved(sizes, rounds, seed)


# --- 7. the refinement -------------------------------------------------------------------


def section_refine(limit: int | None) -> None:
    """``refine()`` (banded NLP, IPOPT fallback) on the stored inexact ``plan()`` problems."""
    sys.path.insert(0, str(FsPath(__file__).parent))
    from bench_refine import CORPUS, load_corpus, run_new  # imports casadi: only here

    cases = load_corpus(CORPUS)[:limit]
    print(f"\n== 7. refinement of {len(cases)} inexact plan() relaxations "
          f"(benchmarks/data/refine_corpus.npz, as bench_refine.py 'new') ==")
    runs = [(case, run_new(case)) for case in cases]
    times = sorted(run.time for _, run in runs)
    n_nodes = [case.problem.n for case in cases]
    q90 = times[min(len(times) - 1, int(0.9 * len(times)))]
    print(f"accepted {sum(run.success for _, run in runs)} of {len(runs)}; nodes "
          f"{min(n_nodes)}-{max(n_nodes)}; time median {statistics.median(times):.3f} s, "
          f"90 % {q90:.3f} s, max {times[-1]:.3f} s")
    slow = max(runs, key=lambda cr: cr[1].time)
    print(f"slowest: {slow[0].key} (n={slow[0].problem.n}): {slow[1].time:.3f} s, "
          f"{slow[1].status}")


# --- 8. straight moves and a 30-edge order ------------------------------------------------

#: The slowest straight move of the trust fuzz's draws (rest to rest).
SLOW_STRAIGHT = (27.337, sp.Limits(v_max=1.0903, a_max=0.3025, a_lat_max=1.0, j_max=1.9522))


def thirty_edge_order() -> dict[str, Any]:
    """A deterministic VDA 5050 order: 31 nodes on a gently winding line, 30 straight edges.

    The nodes allow a deviation of 0.1 m, so the corners are rounded and driven through.
    """
    k = np.arange(31)
    x = 4.9 * k
    y = 1.5 * np.sin(k / 3.0)
    nodes = [{"nodeId": f"N{i}", "sequenceId": 2 * i, "released": True,
              "nodePosition": {"x": float(x[i]), "y": float(y[i]), "mapId": "hall",
                               "allowedDeviationXy": 0.1},
              "actions": []} for i in range(31)]
    edges = [{"edgeId": f"E{i}", "sequenceId": 2 * i + 1, "released": True,
              "startNodeId": f"N{i}", "endNodeId": f"N{i + 1}", "actions": []}
             for i in range(30)]
    return {"headerId": 1, "timestamp": "2026-01-01T00:00:00Z", "version": "2.0.0",
            "manufacturer": "bench", "serialNumber": "1", "orderId": "thirty-edges",
            "orderUpdateId": 0, "nodes": nodes, "edges": edges}


def section_straight(repeats: int, count: int) -> None:
    sys.path.insert(0, str(ROOT / "tests"))
    from oracles import ruckig_move
    from trust_fuzz import draw_case

    print(f"\n== 8. straight moves (the trust fuzz's draws, seed 0, {count} moves, all "
          f"states) and a 30-edge order, medians of {repeats} ==")
    rng = np.random.default_rng(0)
    rows = []
    for case in [draw_case(rng) for _ in range(count)]:
        path = sp.Path.from_segments([Line(case.length)])
        kw = {"v0": case.v0, "a0": case.a0, "vf": case.vf, "af": case.af}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                prof = sp.plan(path, case.limits, **kw)
            except sp.SpeedplanError:
                continue  # refused or infeasible: not a timing
            t = median_time(lambda p=path, c=case, k=kw: sp.plan(p, c.limits, **k), repeats)
        ref = ruckig_move(case.length, case.limits, **kw).duration
        rows.append((t, prof, ref, not any(kw.values())))
    times = sorted(r[0] for r in rows)
    rest = sorted(r[0] for r in rows if r[3])
    ratio = [r[1].duration / r[2] - 1.0 for r in rows if r[2]]
    print(f"plan() on {len(rows)} feasible moves: median {1e3 * statistics.median(times):.2f} "
          f"ms, 90 % {1e3 * times[int(0.9 * (len(times) - 1))]:.2f} ms, max "
          f"{1e3 * times[-1]:.2f} ms; duration / ruckig - 1: max {max(ratio):.1e}, "
          f"min {min(ratio):.1e}")
    if rest:
        print(f"  of them {len(rest)} rest to rest: median {1e3 * statistics.median(rest):.2f} ms, "
              f"max {1e3 * rest[-1]:.2f} ms")
    length, lim = SLOW_STRAIGHT
    path = sp.Path.from_segments([Line(length)])
    for label, kw in (("closed form", {}), ("default grid, banded backend", {"backend": "banded"})):
        prof = sp.plan(path, lim, **kw)
        t = median_time(lambda k=kw: sp.plan(path, lim, **k), repeats)
        answered = [a.name for a in prof.attempts if a.outcome == "answered"][-1]
        print(f"{length} m rest to rest (v_max={lim.v_max}, a_max={lim.a_max}, j_max="
              f"{lim.j_max}), {label}: {1e3 * t:.2f} ms ({answered}, {prof.s.size} nodes), "
              f"T = {prof.duration:.9f} s, ruckig {ruckig_move(length, lim).duration:.9f} s")
    route = sp.Route.from_vda5050(thirty_edge_order())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rp = sp.plan_route(route, LGV)
        t = median_time(lambda: sp.plan_route(route, LGV), repeats)
    print(f"30-edge order ({route.length:.1f} m, {len(rp.legs)} legs), LGV limits: "
          f"{1e3 * t:.1f} ms, T = {rp.duration:.3f} s")


@contextmanager
def _timed(module: Any, name: str, into: dict[str, list[float]]) -> Iterator[None]:
    """Time every call of ``module.name`` (inclusive) into ``into[name]``."""
    original = getattr(module, name)

    def wrapped(*args: Any, **kwargs: Any) -> Any:
        t0 = time.perf_counter()
        try:
            return original(*args, **kwargs)
        finally:
            into[name].append(time.perf_counter() - t0)

    setattr(module, name, wrapped)
    try:
        yield
    finally:
        setattr(module, name, original)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--import-runs", type=int, default=9)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--seeds", type=int, nargs="+", default=[0],
                    help="section 6: one random draw per seed (the target's is seed 0)")
    ap.add_argument("--quick", action="store_true", help="3 repeats, sizes 1 k and 10 k")
    ap.add_argument("--straight", type=int, default=40, help="section 8: straight moves")
    ap.add_argument("--plans", type=int, default=200,
                    help="section 5: plans per process in the cold-start runs")
    ap.add_argument("--only", nargs="+", type=int, choices=range(1, 9),
                    help="run only these sections")
    ap.add_argument("--baseline", metavar="TREE",
                    help="section 3: also time plan() of the speedplan in TREE (a checkout's "
                         "root), alternating with this one in --rounds rounds")
    ap.add_argument("--nojerk-worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.nojerk_worker:
        nojerk_worker()
        return
    repeats = 3 if args.quick else args.repeats
    sizes = [1000, 10000] if args.quick else [10000, 100000]
    only = set(args.only or range(1, 9))
    print(f"speedplan {sp.__version__} from {os.path.dirname(sp.__file__)}; "
          f"cores: {os.cpu_count()}; load average {os.getloadavg()[0]:.1f}")
    compile_kernel()
    if 1 in only:
        section_stages(repeats)
    if 2 in only:
        section_overhead(repeats)
    if 3 in only:
        section_toppra(repeats, 1 if args.quick else args.rounds, args.baseline)
    if 4 in only:
        section_copp(repeats)
    if 5 in only:
        section_startup(args.import_runs, plans=20 if args.quick else args.plans)
    if 6 in only:
        section_memory(sizes, 3 if args.quick else args.rounds, args.seeds)
    if 7 in only:
        section_refine(20 if args.quick else None)
    if 8 in only:
        section_straight(repeats, 10 if args.quick else args.straight)


if __name__ == "__main__":
    main()

"""Latency of ``plan()``: the distribution (median, p99, max) over fuzzed plans and hard cases.

Usage::

    python benchmarks/bench_latency.py --plans 2000 --seed 0
    python benchmarks/bench_latency.py --plans 300 --baseline /path/to/other/checkout
    python benchmarks/bench_latency.py --cases-only --time-limit 2
    python benchmarks/bench_latency.py --plans 200 --cap 60 --baseline /path/to/checkout

The fuzz mixes straight moves (the trust fuzz's ranges, ``tests/trust_fuzz.py``), curved G2
paths through random waypoints, slow zones, comfort limits (``j_lat_max``, ``yaw_rate_max``)
and moving boundary states. The named cases are plans whose latency or outcome is known to be
hard: a 4 m G2 path with a tiny ``a_max``, a 7-waypoint comfort path, long straight moves
with jerk phases far shorter than the move, a nearly-at-rest braking start, and replanning
from a state sampled off a plan. Every plan is timed on its own (wall clock, after the kernels
are compiled, as by ``speedplan compile``, and one warm-up plan) and its outcome recorded: the
profile's status, or the error's class.

With ``--baseline DIR`` the same measurement is also run on the speedplan checkout in ``DIR``
(a subprocess with ``PYTHONPATH=DIR``) and both are printed side by side, so the two runs
share the machine's load. ``--cap`` stops a plan still running after that many seconds (it
is counted at the cap, outcome ``stopped at ...``), so that a slow checkout finishes.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures import TimeoutError as FuturesTimeout
from dataclasses import dataclass
from pathlib import Path as FsPath
from typing import Any

import numpy as np

HERE = FsPath(__file__).resolve()
sys.path.insert(0, str(HERE.parents[1] / "tests"))


@dataclass(frozen=True)
class Job:
    """One plan: a name, its path, its limits and plan() keywords."""

    name: str
    path: Any
    limits: Any
    kwargs: dict[str, Any]


def _straight(sp: Any, length: float) -> Any:
    return sp.Path.from_waypoints([[0.0, 0.0], [length, 0.0]], kind="polyline")


def named_cases(sp: Any) -> list[Job]:
    """The hard cases, each a plan."""
    from speedplan.io import read_path

    g2 = sp.Path.from_waypoints([
        [0, 0], [0.12426521336474784, -0.11657631877453342],
        [3.021780629947684, 0.018193808385309485], [3.207499798766692, -0.2747489556759499],
        [3.9813199879850347, 0.1445236020023441]])
    g2_lim = sp.Limits(v_max=16.418898422873855, a_max=0.11059941918961164,
                       a_lat_max=0.1453314309003239, j_max=13.58945597172854)
    seven = sp.Path.from_waypoints([[0, 0], [1.2, 0.3], [2.1, -0.4], [3.3, 0.2], [4.4, -0.3],
                                    [5.6, 0.4], [6.6, 0.0]])
    comfort = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5, j_lat_max=0.3,
                        yaw_rate_max=0.4)
    jobs = [
        Job("g2_4m_small_a_max", g2, g2_lim, {}),
        Job("seven_waypoints_comfort", seven, comfort, {}),
        Job("straight_260m", _straight(sp, 260.7535089142938),
            sp.Limits(v_max=1.5796976971681844, a_max=0.05146119099882472, a_lat_max=1.0,
                      j_max=27.003482118818823, a_decel=0.04355096774371088), {}),
        Job("straight_16500m", _straight(sp, 16499.670214826176),
            sp.Limits(v_max=8.402299315275519, a_max=0.060097267955824187, a_lat_max=1.0,
                      j_max=77.08902572383232, a_decel=0.13848130909662754), {}),
        Job("straight_1888m_moving", _straight(sp, 1888.1898887677708),
            sp.Limits(v_max=9.182910031427246, a_max=0.05542921908614846, a_lat_max=1.0,
                      j_max=12.25568225509851),
            {"v0": 1.491030987857941e-05, "a0": -0.019111550739391747}),
    ]
    # Replanning from the state of a plan at t = 3 s on the U-turn, as a controller does.
    u_turn = read_path(HERE.parents[1] / "paths" / "u_turn.json")
    lgv = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        first = sp.plan(u_turn, lgv)
    state = first.at(3.0)
    s = float(state.s[0])
    jobs.append(Job("u_turn_replan_at_3s", u_turn.sub(s), lgv,
                    {"v0": float(state.v[0]), "a0": float(state.a[0])}))
    return jobs


def fuzz_cases(sp: Any, plans: int, seed: int) -> list[Job]:
    """``plans`` random plans: a quarter of each kind (straight, curved, zone, comfort)."""
    from shapely.geometry import box
    from trust_fuzz import draw_case

    rng = np.random.default_rng(seed)

    def log(lo: float, hi: float) -> float:
        return float(10 ** rng.uniform(np.log10(lo), np.log10(hi)))

    jobs: list[Job] = []
    for i in range(plans):
        kind = ("straight", "curved", "zone", "comfort")[i % 4]
        if kind == "straight":
            case = draw_case(rng)
            lim = case.limits
            if (case.v0 > lim.v_max or case.vf > lim.v_max
                    or not -lim.a_decel <= case.a0 <= lim.a_max
                    or not -lim.a_decel <= case.af <= lim.a_max):
                case = type(case)(case.length, lim)  # in range: the latency of a real plan
            jobs.append(Job(f"fuzz_{i}_straight", _straight(sp, case.length), lim,
                            {"v0": case.v0, "a0": case.a0, "vf": case.vf, "af": case.af}))
            continue
        k = int(rng.integers(3, 8))
        scale = log(1.0, 200.0)
        xy = np.cumsum(np.column_stack((rng.uniform(0.3, 1.0, k), rng.uniform(-0.5, 0.5, k))),
                       axis=0) * scale
        xy -= xy[0]
        path = sp.Path.from_waypoints(xy)
        v_max, a_max, j_max = log(0.2, 20.0), log(0.05, 3.0), log(0.05, 20.0)
        extra: dict[str, float] = {}
        if kind == "comfort":
            extra = {"j_lat_max": log(0.1, 2.0), "yaw_rate_max": log(0.2, 2.0)}
        lim = sp.Limits(v_max=v_max, a_max=a_max, a_lat_max=log(0.1, 3.0), j_max=j_max,
                        **extra)
        kwargs: dict[str, Any] = {}
        if kind == "zone":
            x0, x1 = sorted(rng.uniform(0.1, 0.9, 2) * float(xy[-1, 0]))
            kwargs["zones"] = [sp.SpeedZone(box(x0, -1e4, max(x1, x0 + 1e-3), 1e4),
                                            log(0.01, 1.0) * v_max)]
        if rng.random() < 0.3:  # a moving start, gently accelerating or braking
            kwargs["v0"] = float(rng.uniform(0.0, 0.3)) * min(v_max, 0.5)
            if kwargs["v0"] > 0:
                kwargs["a0"] = float(rng.uniform(-0.2, 0.2)) * a_max
        jobs.append(Job(f"fuzz_{i}_{kind}", path, lim, kwargs))
    return jobs


def plan_one(job: Job, time_limit: float | None) -> dict[str, Any]:
    """Plan ``job``: its seconds and outcome."""
    import speedplan as sp

    kwargs = dict(job.kwargs)
    if time_limit is not None:
        kwargs["time_limit"] = time_limit
    t0 = time.perf_counter()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            profile = sp.plan(job.path, job.limits, **kwargs)
        outcome = profile.status
        warned = sorted({w.category.__name__ for w in caught})
    except Exception as exc:  # the outcome is data here
        outcome, warned = type(exc).__name__, []
    return {"name": job.name, "seconds": time.perf_counter() - t0, "outcome": outcome,
            "warnings": warned}


def _warm() -> None:
    import speedplan as sp
    from speedplan.core.jit import compile_families

    compile_families()  # as `speedplan compile`: no plan runs while a kernel compiles
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sp.plan(sp.Path.from_waypoints([[0, 0], [5, 0], [5, 3]]),  # load the kernels
                sp.Limits(2.0, 1.0, 1.0, 0.5))


def run(jobs: list[Job], time_limit: float | None, cap: float | None) -> list[dict[str, Any]]:
    """Plan every job; with ``cap``, in a worker process stopped after ``cap`` seconds."""
    if cap is None:
        return [plan_one(job, time_limit) for job in jobs]
    out: list[dict[str, Any]] = []
    pool = None
    for k, job in enumerate(jobs):
        print(f"\r{k}/{len(jobs)}", end="", file=sys.stderr, flush=True)
        if pool is None:
            pool = ProcessPoolExecutor(1)
            pool.submit(_warm).result()
        future = pool.submit(plan_one, job, time_limit)
        try:
            out.append(future.result(timeout=cap))
        except FuturesTimeout:  # a plan still running at the cap: stopped, counted at it
            for proc in list(getattr(pool, "_processes", {}).values()):
                proc.kill()
            pool.shutdown(wait=True, cancel_futures=True)
            pool = None
            out.append({"name": job.name, "seconds": cap, "outcome": f"stopped at {cap:g} s",
                        "warnings": []})
    if pool is not None:
        pool.shutdown()
    return out


def measure(args: argparse.Namespace) -> dict[str, Any]:
    """Warm up, then time the named cases and the fuzz on the speedplan on ``sys.path``."""
    import speedplan as sp

    _warm()
    cases = run(named_cases(sp), args.time_limit, args.cap)
    fuzz = [] if args.cases_only else run(fuzz_cases(sp, args.plans, args.seed),
                                          args.time_limit, args.cap)
    return {"speedplan": str(FsPath(sp.__file__).parent.parent), "cases": cases, "fuzz": fuzz}


def _stats(rows: list[dict[str, Any]]) -> str:
    if not rows:
        return "-"
    t = np.array([r["seconds"] for r in rows])
    return (f"median {statistics.median(t):7.3f} s  p99 {np.quantile(t, 0.99):7.3f} s  "
            f"max {t.max():7.3f} s  over {t.size}")


def _outcomes(rows: list[dict[str, Any]]) -> str:
    counts: dict[str, int] = {}
    for r in rows:
        counts[r["outcome"]] = counts.get(r["outcome"], 0) + 1
    return ", ".join(f"{k} {v}" for k, v in sorted(counts.items()))


def report(runs: list[tuple[str, dict[str, Any]]]) -> None:
    """Print the named cases and the distributions of every run side by side."""
    labels = [label for label, _ in runs]
    print("named cases (seconds, outcome, warnings):")
    for k, row in enumerate(runs[0][1]["cases"]):
        print(f"  {row['name']}")
        for label, data in runs:
            r = data["cases"][k]
            print(f"    {label:>9}: {r['seconds']:8.3f} s  {r['outcome']:<16} "
                  f"{','.join(r['warnings']) or '-'}")
    for label, data in runs:
        rows = data["cases"] + data["fuzz"]
        print(f"\n{label} ({data['speedplan']}):")
        print(f"  fuzz         {_stats(data['fuzz'])}")
        print(f"  all          {_stats(rows)}")
        print(f"  over 0.5 s   {sum(r['seconds'] > 0.5 for r in rows)} of {len(rows)}")
        print(f"  over 2 s     {sum(r['seconds'] > 2.0 for r in rows)} of {len(rows)}")
        print(f"  outcomes     {_outcomes(data['fuzz'])}")
        slow = sorted(data["fuzz"], key=lambda r: -r["seconds"])[:5]
        print("  slowest fuzz " + "; ".join(f"{r['name']} {r['seconds']:.2f} s {r['outcome']}"
                                             for r in slow))
    if len(runs) == 2:
        a, b = (data["cases"] + data["fuzz"] for _, data in runs)
        changed = [(x["name"], x["outcome"], y["outcome"]) for x, y in zip(a, b, strict=True)
                   if x["outcome"] != y["outcome"]]
        print(f"\noutcomes that differ ({labels[0]} -> {labels[1]}): {len(changed)}")
        for name, x, y in changed[:40]:
            print(f"  {name}: {x} -> {y}")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plans", type=int, default=400, help="fuzzed plans")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--cases-only", action="store_true", help="only the named cases")
    ap.add_argument("--time-limit", type=float, default=None,
                    help="plan(..., time_limit=...) [s] (this checkout only)")
    ap.add_argument("--baseline", default=None,
                    help="another speedplan checkout to measure too, side by side")
    ap.add_argument("--cap", type=float, default=None,
                    help="stop a plan after this many seconds and count it at the cap "
                         "(each plan then runs in a worker process)")
    ap.add_argument("--json", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.json:
        print(json.dumps(measure(args)))
        return
    runs = []
    if args.baseline is not None:
        argv_base = [sys.executable, str(HERE), "--json", "--plans", str(args.plans),
                     "--seed", str(args.seed)] + (["--cases-only"] if args.cases_only else []
                                                  ) + ([] if args.cap is None
                                                       else ["--cap", str(args.cap)])
        env = dict(os.environ, PYTHONPATH=str(FsPath(args.baseline).resolve()))
        done = subprocess.run(argv_base, env=env, capture_output=True, text=True, check=True)
        runs.append(("baseline", json.loads(done.stdout.splitlines()[-1])))
    runs.append(("this", measure(args)))
    report(runs)


if __name__ == "__main__":
    main()

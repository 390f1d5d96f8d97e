"""The banded relaxation's iterations and time on the grids ``plan()`` solves.

The problems: every grid leg of ``bench_latency``'s fuzzed curved, zone and comfort plans (on
their default grids; ``--plans``, ``--seed``), and a right-angle corner at a yaw-rate limit on
uniform user grids of 2-7 mm (``n`` = 3 000 to 10 000): a hard case for an interior-point
method, whose iterate must find where braking meets the curved bound node by node. Each is
solved by the banded relaxation alone (no fallback, no refinement). Printed: how many failed,
iterations (median, mean, 90th percentile, max), the total time and the slowest solve; with
``--baseline DIR`` the same problems are also solved by the speedplan checkout in ``DIR`` (a
subprocess with ``PYTHONPATH=DIR``, the problems passed pickled), side by side with the median
and range of the per-problem iteration ratio.

    python benchmarks/ipm_iterations.py --plans 400 --seed 5 --baseline /path/to/checkout
    python benchmarks/ipm_iterations.py --plans 2000 --seed 11 --min-nodes 7000 --baseline ...
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path as FsPath
from typing import Any

import numpy as np

HERE = FsPath(__file__).resolve().parent
CORNER = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]]
CORNER_LIMITS = dict(v_max=5.0, a_max=0.5, a_lat_max=1.0, j_max=20.0, yaw_rate_max=0.3)


def collect(plans: int, seed: int, min_nodes: int) -> list[tuple[str, Any]]:
    """``(name, problem)`` in the relaxation's units for every grid leg of the jobs.

    Legs of fewer than ``min_nodes`` nodes are left out (the corner grids never are).
    """
    sys.path[:0] = [str(HERE), str(HERE.parent / "tests")]
    from bench_latency import fuzz_cases

    import speedplan as sp
    from speedplan.model import PlanRequest, build_model
    from speedplan.solve.banded import unit_scales

    out: list[tuple[str, Any]] = []

    def add(name: str, path: Any, limits: Any, least: int = 50, **kwargs: Any) -> None:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                model = build_model(PlanRequest.create(path, limits, **kwargs))
        except sp.SpeedplanError:
            return  # refused before any solve: nothing for the relaxation
        for k, leg in enumerate(model.legs):
            problem = getattr(leg, "problem", None)  # closed-form legs have none
            if problem is not None and problem.n >= least:
                out.append((f"{name}/{k}", problem.scaled(*unit_scales(problem))))

    corner = sp.Path.from_waypoints(CORNER)
    for n in (3000, 6000, 8000, 10000):
        add(f"corner_n{n}", corner, sp.Limits(**CORNER_LIMITS), n=n)
    for job in fuzz_cases(sp, plans, seed):
        if not job.name.endswith("_straight"):
            add(job.name, job.path, job.limits, max(50, min_nodes), **job.kwargs)
    return out


Row = tuple[str, int, str, int, float, float, float]


def solve_all(problems_file: str) -> list[Row]:
    """``(name, n, status, iterations, seconds, primal, dual)`` of each problem.

    On a failure the iterations are -1 and the objectives NaN.
    """
    from speedplan.core.errors import SolverError
    from speedplan.solve.banded import solve_unit_relaxation

    with open(problems_file, "rb") as f:
        problems = pickle.load(f)
    solve_unit_relaxation(problems[0][1])  # load or compile the kernel outside the timing
    rows = []
    for name, problem in problems:
        t0 = time.perf_counter()
        try:
            res = solve_unit_relaxation(problem)
            status, iterations = res.status, res.iterations
            primal, dual = res.primal_objective, res.dual_objective
        except SolverError as exc:
            status, iterations, primal, dual = f"SolverError ({exc.status})", -1, np.nan, np.nan
        rows.append((name, problem.n, status, iterations, time.perf_counter() - t0, primal,
                     dual))
    return rows


def summary(label: str, rows: list[Row]) -> None:
    """Print one checkout's failures, iteration counts, largest certified gap and times."""
    its = np.array([r[3] for r in rows if r[3] >= 0])
    gaps = np.array([(r[5] - r[6]) / r[5] for r in rows if r[3] >= 0])
    failed = [f"{r[0]} ({r[1]} nodes): {r[2]}" for r in rows if r[3] < 0]
    secs = np.array([r[4] for r in rows])
    print(f"{label:>9}: {len(failed)} of {len(rows)} failed; iterations median "
          f"{np.median(its):.0f}, mean {its.mean():.1f}, 90% {np.percentile(its, 90):.0f}, "
          f"max {its.max()}; certified gap at most {gaps.max():.1e}; time {secs.sum():.1f} s "
          f"in all, slowest {secs.max():.2f} s")
    for line in failed:
        print(f"{'':>11}{line}")
    corners = [f"{r[1]} nodes: {r[3] if r[3] >= 0 else r[2]}" for r in rows
               if r[0].startswith("corner")]
    print(f"{'':>11}corner at the yaw-rate limit, uniform grids: " + "; ".join(corners))


def main() -> None:
    """Collect the problems, solve them here (and in ``--baseline``), print both."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--plans", type=int, default=400, help="fuzzed plans (a quarter straight, "
                    "which have no grid legs to solve)")
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--min-nodes", type=int, default=0,
                    help="only the fuzzed legs of at least this many nodes (the slow tail)")
    ap.add_argument("--baseline", default=None, help="another speedplan checkout, side by side")
    ap.add_argument("--solve", default=None, help=argparse.SUPPRESS)  # the subprocess's job
    args = ap.parse_args()
    if args.solve is not None:
        print(json.dumps(solve_all(args.solve)))
        return
    problems = collect(args.plans, args.seed, args.min_nodes)
    corners = sum(name.startswith("corner") for name, _ in problems)
    print(f"{len(problems) - corners} grid legs of {args.plans} fuzzed plans (seed {args.seed}"
          f"{f', at least {args.min_nodes} nodes' if args.min_nodes else ''}) and "
          f"{corners} corner grids; sizes median {np.median([p.n for _, p in problems]):.0f}, "
          f"max {max(p.n for _, p in problems)} nodes")
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "problems.pkl")
        with open(path, "wb") as f:
            pickle.dump(problems, f)
        runs = [("this", solve_all(path))]
        if args.baseline is not None:
            env = dict(os.environ, PYTHONPATH=str(FsPath(args.baseline).resolve()))
            done = subprocess.run([sys.executable, __file__, "--solve", path], env=env,
                                  capture_output=True, text=True, check=True)
            runs.append(("baseline", json.loads(done.stdout.splitlines()[-1])))
    for label, rows in runs:
        summary(label, rows)
    if len(runs) == 2:
        ours, base = runs[0][1], runs[1][1]
        ratio = np.array([a[3] / b[3] for a, b in zip(ours, base, strict=True)
                          if a[3] > 0 and b[3] > 0])
        both = [(a, b) for a, b in zip(ours, base, strict=True) if a[3] >= 0 and b[3] >= 0]
        apart = max(abs(a[5] - b[5]) / b[5] for a, b in both)
        print(f"iterations this / baseline, per problem solved by both: median "
              f"{np.median(ratio):.3f}, range {ratio.min():.2f}-{ratio.max():.2f}; "
              f"time {sum(r[4] for r in ours) / sum(r[4] for r in base):.3f}; "
              f"objectives agree to {apart:.1e} (relative)")


if __name__ == "__main__":
    main()

"""Where ``plan()``'s wall time goes on the bundled sample paths.

Usage::

    python benchmarks/bench_plan.py --repeats 5

For each file in ``paths/`` (default grid, LGV limits v_max=2, a_max=1, a_lat_max=1, j_max=0.5):
the median wall time of ``plan()``, of its relaxation (``solution.solve_time``), of
``verify()`` (which ``plan()`` runs once: 1 ms sampling in time) and of ``sample(0.01)``. The
first call in the process (loading compiled kernels) is excluded.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import speedplan as sp
from speedplan.io import read_path

PATHS = Path(__file__).resolve().parents[1] / "paths"
LIMITS = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)


def median_time(call: Callable[[], Any], repeats: int) -> tuple[float, Any]:
    times, result = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = call()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    files = sorted(p for p in PATHS.iterdir() if p.suffix in (".csv", ".json"))
    t0 = time.perf_counter()
    sp.plan(read_path(str(files[0])), LIMITS)
    print(f"first plan() in this process (loads compiled kernels): "
          f"{time.perf_counter() - t0:.2f} s, excluded")
    print(f"{'path':<22} {'n':>6} {'duration [s]':>12} {'plan [s]':>9} {'relax [s]':>10}"
          f" {'verify [s]':>11} {'sample(0.01) [s]':>17}")
    for file in files:
        path = read_path(str(file))
        t_plan, prof = median_time(lambda p=path: sp.plan(p, LIMITS), args.repeats)
        t_verify, _ = median_time(prof.verify, args.repeats)
        t_sample, _ = median_time(lambda pr=prof: pr.sample(0.01), args.repeats)
        print(f"{file.name:<22} {prof.s.size:>6} {prof.duration:>12.3f} {t_plan:>9.3f}"
              f" {prof.solution.solve_time:>10.4f} {t_verify:>11.3f} {t_sample:>17.4f}")


if __name__ == "__main__":
    main()

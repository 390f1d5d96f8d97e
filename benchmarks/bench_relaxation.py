"""Time the SOCP relaxation: the paper's plain formulation, our Clarabel, the banded IPM.

Paper-style instances (h = 1, w_max uniform in [0.01, 100] per node, constant A and J drawn as
in the paper), all in the same run, median of ``--repeats`` solves each. ``plain`` is the
paper's eq. (relax_SOCP) with three cones per node assembled row by row in Python and solved by
Clarabel (``benchmarks/plain_clarabel.py``); times include building the problem. Clarabel
settings worth knowing are measured as separate rows: ``clarabel-noir`` (iterative refinement
off) and ``clarabel-tol6`` (gap and feasibility tolerances 1e-6 instead of 1e-8). A second
table times the exact no-jerk pass (``solve_discrete`` with ``J = inf``) up to n = 10^6.
The last column, wall time (building included, as in the time column) per node and iteration,
shows where the banded method's working set (about 1.3 kB per node) leaves the CPU caches.

    cd benchmarks && python bench_relaxation.py --sizes 1000 10000 100000 --repeats 5
"""

from __future__ import annotations

import argparse
import itertools
import os
import statistics
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from plain_clarabel import solve_plain

from speedplan import solve_discrete
from speedplan.solve.banded import solve_relaxation_banded
from speedplan.solve.clarabel_ import default_settings, solve_relaxation
from speedplan.solve.paper import paper_instance
from speedplan.solve.problem import DiscreteProblem


def instance(n: int, seed: int) -> DiscreteProblem:
    inst = paper_instance("rnd", "cnst", "cnst", n=n, seed=seed)
    return DiscreteProblem(
        s=np.arange(n, dtype=float), w_max=inst.w_max, accel=inst.A, decel=inst.A,
        jerk=inst.J,
    )


def clarabel_variant(name: str) -> Callable[[DiscreteProblem], Any]:
    """Our Clarabel formulation with one setting changed (``name`` says which)."""
    settings = default_settings()
    if name == "clarabel-noir":
        settings.iterative_refinement_enable = False
    elif name == "clarabel-tol6":
        settings.tol_gap_abs = settings.tol_gap_rel = 1e-6
        settings.tol_feas = 1e-6
    return lambda p: solve_relaxation(p, settings)


def timed(solve: Callable[[Any], Any], problem: Any, repeats: int) -> tuple[float, Any]:
    """Median wall time of ``repeats`` calls ``solve(problem)`` and the last result."""
    times: list[float] = []
    result = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = solve(problem)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1000, 10000, 100000])
    parser.add_argument("--nojerk-sizes", type=int, nargs="+", default=[10000, 100000, 1000000])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--clarabel-max", type=int, default=100000,
                        help="skip Clarabel above this n")
    parser.add_argument("--variants-max", type=int, default=10000,
                        help="skip the Clarabel settings variants above this n")
    parser.add_argument("--plain-max", type=int, default=10000,
                        help="skip the plain formulation above this n")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    t0 = time.perf_counter()
    solve_relaxation_banded(instance(50, args.seed))
    print(f"cores: {os.cpu_count()}  repeats: {args.repeats}  (median wall time per solve)")
    print(f"banded first call in this process (loads or compiles the numba kernel): "
          f"{time.perf_counter() - t0:.2f} s, excluded from the table")
    header = (f"{'backend':<14} {'n':>8} {'time [s]':>10} {'plain / time':>13}"
              f" {'rel obj diff':>13} {'iters':>6} {'status':>13} {'ns/(node*iter)':>15}")
    print(header)
    banded_times: dict[int, float] = {}
    for n in args.sizes:
        problem = instance(n, args.seed)
        plain_time: float | None = None
        ref_obj: float | None = None
        if n <= args.plain_max:
            inst = paper_instance("rnd", "cnst", "cnst", n=n, seed=args.seed)
            plain_time, plain = timed(lambda _p, i=inst: solve_plain(i.w_max, i.A, i.J),
                                      problem, args.repeats)
            ref_obj = plain[0]
            print(f"{'plain':<14} {n:>8} {plain_time:>10.4f} {1.0:>13.2f} {0.0:>13.1e}")
        rows: list[tuple[str, Callable[[DiscreteProblem], Any]]] = []
        if n <= args.clarabel_max:
            rows.append(("clarabel", solve_relaxation))
        if n <= args.variants_max:
            rows += [(v, clarabel_variant(v)) for v in ("clarabel-noir", "clarabel-tol6")]
        rows.append(("banded", solve_relaxation_banded))
        for name, solve in rows:
            t, res = timed(solve, problem, args.repeats)
            if name == "banded":
                banded_times[n] = t
            if ref_obj is None:  # no plain run at this size: compare with our Clarabel
                ref_obj = res.primal_objective
            speedup = f"{plain_time / t:>13.2f}" if plain_time else f"{'-':>13}"
            diff = (res.primal_objective - ref_obj) / ref_obj
            per_node_iter = t / (n * max(res.iterations, 1)) * 1e9
            print(f"{name:<14} {n:>8} {t:>10.4f} {speedup} {diff:>13.1e}"
                  f" {res.iterations:>6} {res.status:>13} {per_node_iter:>15.0f}")
    sizes = sorted(banded_times)
    for small, big in itertools.pairwise(sizes):
        print(f"banded time({big}) / time({small}) = "
              f"{banded_times[big] / banded_times[small]:.2f}  (n ratio {big / small:g})")

    print("\nno-jerk case: exact forward/backward pass, solve_discrete(w_max, A, J=inf)")
    print(f"{'n':>8} {'time [s]':>10}")
    for n in args.nojerk_sizes:
        inst = paper_instance("rnd", "cnst", "cnst", n=n, seed=args.seed)
        t, _ = timed(lambda _p, i=inst: solve_discrete(i.w_max, i.A, np.inf), None,
                     args.repeats)
        print(f"{n:>8} {t:>10.4f}")


if __name__ == "__main__":
    main()

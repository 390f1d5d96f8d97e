"""Time the SOCP relaxation: the paper's formulation built plainly, our Clarabel, banded IPM.

Paper-style instances (h = 1, w_max uniform in [0.01, 100] per node, constant A and J drawn as
in the paper), all in the same run, median of ``--repeats`` solves each. ``plain`` is the
paper's eq. (relax_SOCP) with three cones per node assembled row by row in Python and solved by
Clarabel (``benchmarks/plain_clarabel.py``); times include building the problem.

    python benchmarks/bench_relaxation.py --sizes 1000 10000 100000 --repeats 5
"""

from __future__ import annotations

import argparse
import itertools
import os
import statistics
import time

import numpy as np
from plain_clarabel import solve_plain

from speedplan.solve.banded import solve_relaxation_banded
from speedplan.solve.clarabel_ import solve_relaxation
from speedplan.solve.paper import paper_instance
from speedplan.solve.problem import DiscreteProblem


def instance(n: int, seed: int) -> DiscreteProblem:
    inst = paper_instance("rnd", "cnst", "cnst", n=n, seed=seed)
    return DiscreteProblem(
        s=np.arange(n, dtype=float), w_max=inst.w_max, accel=inst.A, decel=inst.A,
        jerk=inst.J,
    )


def timed(solve, problem, repeats):
    times, result = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = solve(problem)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1000, 10000, 100000])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--clarabel-max", type=int, default=100000,
                        help="skip Clarabel above this n")
    parser.add_argument("--plain-max", type=int, default=10000,
                        help="skip the plain formulation above this n")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    print(f"cores: {os.cpu_count()}  repeats: {args.repeats}  (median wall time per solve)")
    header = f"{'backend':<9} {'n':>8} {'time [s]':>10} {'x Clarabel':>11} {'rel obj diff':>13}"
    header += f" {'iters':>6} {'status':>12}"
    print(header)
    banded_times = {}
    for n in args.sizes:
        problem = instance(n, args.seed)
        ref_time = ref = None
        if n <= args.plain_max:
            inst = paper_instance("rnd", "cnst", "cnst", n=n, seed=args.seed)
            plain_time, plain = timed(lambda _p, i=inst: solve_plain(i.w_max, i.A, i.J),
                                      problem, args.repeats)
            print(f"{'plain':<9} {n:>8} {plain_time:>10.4f} {'(baseline)':>11}")
        if n <= args.clarabel_max:
            ref_time, ref = timed(solve_relaxation, problem, args.repeats)
            print(f"{'clarabel':<9} {n:>8} {ref_time:>10.4f} {1.0:>11.2f} {0.0:>13.1e}"
                  f" {ref.iterations:>6} {ref.status:>12}")
        b_time, res = timed(solve_relaxation_banded, problem, args.repeats)
        banded_times[n] = b_time
        ratio = f"{b_time / ref_time:>11.3f}" if ref_time else f"{'-':>11}"
        diff = (f"{(res.primal_objective - ref.primal_objective) / ref.primal_objective:>13.1e}"
                if ref else f"{'-':>13}")
        print(f"{'banded':<9} {n:>8} {b_time:>10.4f} {ratio} {diff} {res.iterations:>6}"
              f" {res.status:>12}")
        if n <= args.plain_max:
            ours = min(t for t in (ref_time, b_time) if t is not None)
            print(f"{'':<9} {n:>8} plain / fastest of ours = {plain_time / ours:.2f}; objective"
                  f" difference {(plain[0] - res.primal_objective) / plain[0]:.1e}")
    sizes = sorted(banded_times)
    for small, big in itertools.pairwise(sizes):
        print(f"banded time({big}) / time({small}) = "
              f"{banded_times[big] / banded_times[small]:.2f}  (n ratio {big / small:g})")


if __name__ == "__main__":
    main()

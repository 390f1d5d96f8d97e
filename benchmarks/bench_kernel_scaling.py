"""Memory per node and the time(100 k) / time(10 k) ratio of ``solve_discrete``, interleaved.

Paper instances (rnd/cnst/cnst, h = 1). The sizes are run in turn, ``--rounds`` times
(10 k, 100 k, 10 k, 100 k, ...), so that a slow phase of the shared machine hits both sizes
alike (the order matters: at 100 k nodes the working set leaves the L3 cache). Prints the
median of each size and their ratio, and the tracemalloc peak of one solve per size, in
bytes per node (a separate run: tracemalloc slows allocation down).

    python benchmarks/bench_kernel_scaling.py --rounds 7
"""

from __future__ import annotations

import argparse
import statistics
import time
import tracemalloc

from speedplan import solve_discrete
from speedplan.solve.paper import paper_instance


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10000, 100000])
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    insts = {n: paper_instance("rnd", "cnst", "cnst", n=n, seed=args.seed) for n in args.sizes}
    small = paper_instance("rnd", "cnst", "cnst", n=200, seed=args.seed)
    solve_discrete(small.w_max, small.A, small.J, backend="banded")  # load the kernel
    for n, inst in insts.items():
        tracemalloc.start()
        sol = solve_discrete(inst.w_max, inst.A, inst.J, backend="banded")
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        print(f"n={n:>7}: tracemalloc peak {peak / n:6.0f} bytes/node  ({sol.backend}, "
              f"{sol.relaxation.iterations if sol.relaxation else 0} iterations)")
    times: dict[int, list[float]] = {n: [] for n in args.sizes}
    for _ in range(args.rounds):
        for n, inst in insts.items():
            t0 = time.perf_counter()
            solve_discrete(inst.w_max, inst.A, inst.J, backend="banded")
            times[n].append(time.perf_counter() - t0)
    med = {n: statistics.median(t) for n, t in times.items()}
    for n in args.sizes:
        print(f"n={n:>7}: median {med[n]:.4f} s over {args.rounds} interleaved rounds "
              f"(min {min(times[n]):.4f}, max {max(times[n]):.4f})")
    for a, b in zip(args.sizes, args.sizes[1:], strict=False):
        print(f"time({b}) / time({a}) = {med[b] / med[a]:.2f}")


if __name__ == "__main__":
    main()

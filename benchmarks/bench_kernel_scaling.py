"""Memory per node and the time(100 k) / time(10 k) ratio of ``solve_discrete``, interleaved.

Paper instances (rnd/cnst/cnst unless ``--family``, h = 1). The sizes are run in turn,
``--rounds`` times (10 k, 100 k, 10 k, 100 k, ...), so that a slow phase of the shared
machine hits both sizes alike (the order matters: at 100 k nodes the working set leaves the
L3 cache). Prints, per seed, the tracemalloc peak of one solve per size in bytes per node (a
separate run: tracemalloc slows allocation down), the median time of each size, and the
ratio split into its two factors: the interior-point iterations (a property of the random
draw and of the method) and the time per node and iteration (memory traffic and cache).

``--iterations`` prints instead how the iteration count grows with the grid, for this
kernel and for Clarabel on the same instances (``solve_discrete(backend="clarabel")``, the
generic interior-point method on the same SOCP), over several families and seeds: the
growth is the method class's, not this kernel's alone.

    python benchmarks/bench_kernel_scaling.py --rounds 7
    python benchmarks/bench_kernel_scaling.py --rounds 7 --seeds 0 1 2 3
    python benchmarks/bench_kernel_scaling.py --iterations --sizes 1000 10000 100000
"""

from __future__ import annotations

import argparse
import itertools
import math
import statistics
import time
import tracemalloc

from speedplan import solve_discrete
from speedplan.solve.paper import FAMILIES, PaperInstance, paper_instance

BENCH_FAMILY = ("rnd", "cnst", "cnst")
#: Families for ``--iterations``: the bench family and those whose iterations grow most.
GROWTH_FAMILIES = (BENCH_FAMILY, ("rnd", "rnd", "cnst"), ("rnd", "cnst", "rnd"),
                   ("rnd", "reg", "cnst"), ("pw lin", "cnst", "cnst"))


def _solve(inst: PaperInstance, backend: str = "banded") -> tuple[float, int, str]:
    """Wall time, iterations and backend of one ``solve_discrete`` of ``inst``."""
    t0 = time.perf_counter()
    sol = solve_discrete(inst.w_max, inst.A, inst.J, backend=backend)
    elapsed = time.perf_counter() - t0
    relax = sol.relaxation
    return elapsed, relax.iterations if relax else 0, relax.backend if relax else sol.backend


def interleaved(sizes: list[int], rounds: int, seed: int,
                family: tuple[str, str, str] = BENCH_FAMILY) -> None:
    """Print memory, times, iterations and the ratio's two factors for one draw per size."""
    insts = {n: paper_instance(*family, n=n, seed=seed) for n in sizes}
    iters: dict[int, int] = {}
    for n, inst in insts.items():
        tracemalloc.start()
        _, iters[n], backend = _solve(inst)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        print(f"seed {seed} n={n:>7}: tracemalloc peak {peak / n:6.0f} bytes/node  "
              f"({backend}, {iters[n]} iterations)")
    times: dict[int, list[float]] = {n: [] for n in sizes}
    for _ in range(rounds):
        for n, inst in insts.items():
            times[n].append(_solve(inst)[0])
    med = {n: statistics.median(t) for n, t in times.items()}
    for n in sizes:
        per = 1e9 * med[n] / (n * max(iters[n], 1))
        print(f"seed {seed} n={n:>7}: median {med[n]:.4f} s over {rounds} interleaved rounds "
              f"(min {min(times[n]):.4f}, max {max(times[n]):.4f}); "
              f"{per:.0f} ns per node and iteration")
    for a, b in itertools.pairwise(sizes):
        it_ratio = iters[b] / max(iters[a], 1)
        print(f"seed {seed} time({b}) / time({a}) = {med[b] / med[a]:.2f} = iterations "
              f"{iters[b]}/{iters[a]} ({it_ratio:.3f}) x per node and iteration "
              f"{med[b] / med[a] / it_ratio:.2f}")


def iteration_growth(sizes: list[int], seeds: list[int]) -> None:
    """Iterations of this kernel and of Clarabel per family, seed and size."""
    print(f"iterations (banded / clarabel) at n = {', '.join(map(str, sizes))}; "
          "'*' marks a solve answered by the other backend")
    growth: dict[str, list[float]] = {"banded": [], "clarabel": []}
    for family in GROWTH_FAMILIES:
        assert family in FAMILIES
        for seed in seeds:
            cells, counts = [], {"banded": [], "clarabel": []}
            for n in sizes:
                inst = paper_instance(*family, n=n, seed=seed)
                pair = []
                for backend in counts:
                    _, its, used = _solve(inst, backend)
                    counts[backend].append(its)
                    pair.append(f"{its}{'' if used == backend else '*'}")
                cells.append("/".join(pair))
            decades = math.log10(sizes[-1] / sizes[0])
            for backend, its in counts.items():
                growth[backend].append((its[-1] / its[0]) ** (1 / decades) - 1)
            print(f"{'/'.join(family):<18} seed {seed}: " + "  ".join(cells))
    for backend, g in growth.items():
        print(f"{backend:>8}: iterations grow by {100 * statistics.median(g):.0f} % per decade "
              f"of nodes (median over {len(g)} draws; range {100 * min(g):.0f} to "
              f"{100 * max(g):.0f} %)")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=None,
                        help="grid sizes (default 10000 100000; 1000 10000 100000 with "
                             "--iterations)")
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--seeds", type=int, nargs="+", default=[0])
    parser.add_argument("--iterations", action="store_true",
                        help="iteration growth of this kernel and of Clarabel instead")
    args = parser.parse_args(argv)
    small = paper_instance(*BENCH_FAMILY, n=200, seed=0)
    _solve(small)  # load the kernel
    if args.iterations:
        iteration_growth(args.sizes or [1000, 10000, 100000], args.seeds)
        return
    for seed in args.seeds:
        interleaved(args.sizes or [10000, 100000], args.rounds, seed)


if __name__ == "__main__":
    main()

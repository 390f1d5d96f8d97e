"""Reproduce the paper's Table 1 (18 families, n = 1000) with speedplan.

Usage::

    python benchmarks/paper_table.py --instances 20 --n 1000 [--json out.json]

Columns as in the paper: non-exact count, max and mean jerk error of the relaxed solution,
max and mean gap [%] over the non-exact instances (after IPOPT refinement), mean time [s]
of the relaxation. The paper used 1000 instances per family and MOSEK on an 8-core M1 Pro.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

from speedplan import solve_discrete
from speedplan.solve.paper import FAMILIES, paper_instance

# The paper's Table 1, in FAMILIES order: non-exact, max err, mean err, max gap %, mean gap %, t.
PAPER = [
    (0, 8.5519e-08, 8.5519e-11, None, None, 0.17068),
    (0, 0, 0, None, None, 0.1533),
    (0, 0, 0, None, None, 0.20595),
    (0, 0, 0, None, None, 0.17975),
    (4, 0.16594, 0.0002596, 0.004401, 6.803e-06, 0.1747),
    (0, 7.9644e-08, 9.7622e-11, None, None, 0.1673),
    (0, 0, 0, None, None, 0.19426),
    (0, 0, 0, None, None, 0.18469),
    (0, 0, 0, None, None, 0.17357),
    (756, 1.0218, 0.2061, 0.17484, 0.0098672, 0.18201),
    (45, 0.59223, 0.0080017, 0.067108, 0.00034977, 0.15341),
    (0, 0, 0, None, None, 0.15199),
    (788, 0.96156, 0.20684, 0.19155, 0.010135, 0.17649),
    (251, 2.0381, 0.11864, 0.64832, 0.011838, 0.21448),
    (191, 2.3979, 0.097524, 0.80218, 0.013251, 0.15705),
    (808, 1.1569, 0.22148, 0.27889, 0.010681, 0.19329),
    (42, 0.70596, 0.0080485, 0.065445, 0.00038971, 0.19225),
    (0, 0, 0, None, None, 0.21015),
]


def run_family(family, instances, n, seed0, backend):
    errs, gaps, times, non_exact, failures = [], [], [], 0, 0
    for k in range(instances):
        inst = paper_instance(*family, n=n, seed=seed0 + k)
        try:
            sol = solve_discrete(inst.w_max, inst.A, inst.J, backend=backend)
        except Exception as exc:  # report, keep going
            failures += 1
            print(f"  {family} seed {seed0 + k}: {type(exc).__name__}: {exc}", file=sys.stderr)
            continue
        errs.append(sol.relaxation.jerk_violation)
        times.append(sol.relaxation.time)
        if not sol.exact:
            non_exact += 1
            gaps.append(100.0 * sol.gap)
    return {
        "family": list(family),
        "instances": instances,
        "non_exact": non_exact,
        "failures": failures,
        "max_err": float(np.max(errs)) if errs else None,
        "mean_err": float(np.mean(errs)) if errs else None,
        "max_gap_pct": float(np.max(gaps)) if gaps else None,
        "mean_gap_pct": float(np.mean(gaps)) if gaps else None,
        "mean_time": float(np.mean(times)) if times else None,
        "median_time": float(np.median(times)) if times else None,
    }


def _fmt(x, spec=".3g"):
    return "N/A" if x is None else format(x, spec)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--instances", type=int, default=20, help="instances per family (paper: 1000)")
    ap.add_argument("--n", type=int, default=1000, help="grid size (paper: 1000)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--backend", default="clarabel")
    ap.add_argument("--json", help="write the rows to this JSON file")
    args = ap.parse_args(argv)
    print(f"# speedplan vs paper Table 1: n={args.n}, {args.instances} instances/family, "
          f"backend={args.backend}, {os.cpu_count()} cores")
    print("| W | A | J | non-exact (ours / paper) | max jerk err (ours / paper) | mean jerk err "
          "(ours / paper) | max gap % (ours / paper) | mean gap % (ours / paper) | mean time s "
          "(ours / paper) |")
    print("|---|---|---|---|---|---|---|---|---|")
    rows = []
    t0 = time.perf_counter()
    for i, family in enumerate(FAMILIES):
        row = run_family(family, args.instances, args.n, args.seed + 1000 * i, args.backend)
        rows.append(row)
        p = PAPER[i]
        print(f"| {family[0]} | {family[1]} | {family[2]} "
              f"| {row['non_exact']}/{row['instances']} / {p[0]}/1000 "
              f"| {_fmt(row['max_err'])} / {_fmt(p[1])} | {_fmt(row['mean_err'])} / {_fmt(p[2])} "
              f"| {_fmt(row['max_gap_pct'])} / {_fmt(p[3])} "
              f"| {_fmt(row['mean_gap_pct'])} / {_fmt(p[4])} "
              f"| {_fmt(row['mean_time'], '.4f')} / {p[5]} |", flush=True)
    print(f"# total wall time {time.perf_counter() - t0:.1f} s")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"n": args.n, "instances": args.instances, "rows": rows}, fh, indent=1)


if __name__ == "__main__":
    main()

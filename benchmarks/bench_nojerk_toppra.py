"""No-jerk case: speedplan's exact O(n) pass against TOPP-RA on the same problems.

Usage::

    python benchmarks/bench_nojerk_toppra.py --sizes 1000 10000 100000 --repeats 5

A straight path of length L (1-DOF in TOPP-RA: the joint is the arc length) with speed and
acceleration limits, rest to rest. Both compute the time-optimal law without jerk limits; we
print durations (ours from the discrete objective on the same grid) and the time ratio.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np
import toppra as ta
import toppra.algorithm as algo
import toppra.constraint as constraint

from speedplan import solve_discrete

ta.setup_logging("WARNING")


def ours(L, n, v_max, a_max):
    h = L / (n - 1)
    t0 = time.perf_counter()
    sol = solve_discrete(np.full(n, v_max**2), 2 * a_max, np.inf, h=h)
    elapsed = time.perf_counter() - t0
    # Exact duration of the piecewise-constant-acceleration law through the nodes.
    v = np.sqrt(sol.w)
    duration = float(np.sum(2 * h / (v[:-1] + v[1:])))
    return duration, elapsed


def toppra_(L, n, v_max, a_max):
    t0 = time.perf_counter()
    path = ta.SplineInterpolator(np.linspace(0, 1, 2), np.array([[0.0], [L]]))
    pc_vel = constraint.JointVelocityConstraint(np.array([[-v_max, v_max]]))
    pc_acc = constraint.JointAccelerationConstraint(np.array([[-a_max, a_max]]))
    inst = algo.TOPPRA([pc_vel, pc_acc], path, gridpoints=np.linspace(0, 1, n),
                       parametrizer="ParametrizeConstAccel")
    traj = inst.compute_trajectory(0, 0)
    elapsed = time.perf_counter() - t0
    return float(traj.duration), elapsed


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[1000, 10000, 100000])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--length", type=float, default=30.0)
    args = ap.parse_args(argv)
    v_max, a_max = 2.0, 1.0
    exact = args.length / v_max + v_max / a_max
    print(f"cores: {os.cpu_count()}  L = {args.length} m  v_max = {v_max}  a_max = {a_max}  "
          f"exact duration {exact:.6f} s  (median of {args.repeats})")
    print(f"{'n':>8s} {'ours [s]':>10s} {'toppra [s]':>11s} {'toppra/ours':>12s} "
          f"{'T ours':>10s} {'T toppra':>10s}")
    for n in args.sizes:
        a = [ours(args.length, n, v_max, a_max) for _ in range(args.repeats)]
        b = [toppra_(args.length, n, v_max, a_max) for _ in range(args.repeats)]
        ta_, tb = np.median([x[1] for x in a]), np.median([x[1] for x in b])
        print(f"{n:8d} {ta_:10.5f} {tb:11.5f} {tb / ta_:12.1f} {a[0][0]:10.5f} {b[0][0]:10.5f}",
              flush=True)


if __name__ == "__main__":
    main()

"""Straight rest-to-rest moves: ``plan()`` against ruckig, durations and wall time.

Usage::

    python benchmarks/bench_ruckig.py --repeats 7

ruckig computes the exact time-optimal jerk-limited motion between two states of one axis;
on a straight line that is the optimum ``plan()`` must reach (ruckig cannot follow a curved
path, so the comparison is limited to lines). For each length (LGV limits ``v_max = 2``,
``a_max = 1``, ``j_max = 0.5``), prints both durations, their relative difference and the
median wall time of each call (ruckig's ``calculate``; ``plan()`` on its default grid plus
``sample(0.01)``, the trajectory a controller receives). One warm-up call is excluded.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ruckig import InputParameter, Result, Ruckig, Trajectory

import speedplan as sp

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_plan

LIMITS = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)


def median_time(call: Callable[[], Any], repeats: int) -> tuple[float, Any]:
    """``bench_plan.median_time`` after one warm-up call."""
    call()
    return bench_plan.median_time(call, repeats)


def ruckig_duration(length: float, lim: sp.Limits) -> float:
    otg, inp, traj = Ruckig(1), InputParameter(1), Trajectory(1)
    inp.current_position, inp.current_velocity, inp.current_acceleration = [0.0], [0.0], [0.0]
    inp.target_position, inp.target_velocity, inp.target_acceleration = [length], [0.0], [0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [lim.v_max], [lim.a_max], [lim.j_max]
    if otg.calculate(inp, traj) != Result.Working:
        raise RuntimeError(f"ruckig found no motion for L = {length}")
    return float(traj.duration)


def ours(length: float, lim: sp.Limits) -> float:
    path = sp.Path.from_waypoints([[0, 0], [length, 0]], kind="polyline")
    profile = sp.plan(path, lim)
    profile.sample(0.01)
    return float(profile.duration)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--lengths", type=float, nargs="+", default=[0.5, 3.0, 30.0, 300.0])
    args = parser.parse_args()
    print(f"limits: v_max={LIMITS.v_max}, a_max={LIMITS.a_max}, j_max={LIMITS.j_max}; "
          f"medians of {args.repeats}")
    print(f"{'L [m]':>8} {'T ours [s]':>11} {'T ruckig [s]':>13} {'rel. diff':>10} "
          f"{'ours [ms]':>10} {'ruckig [ms]':>12}")
    for length in args.lengths:
        t_ours, d_ours = median_time(lambda L=length: ours(L, LIMITS), args.repeats)
        t_rk, d_rk = median_time(lambda L=length: ruckig_duration(L, LIMITS), args.repeats)
        print(f"{length:8.1f} {d_ours:11.4f} {d_rk:13.4f} {(d_ours - d_rk) / d_rk:10.1e} "
              f"{1e3 * t_ours:10.2f} {1e3 * t_rk:12.3f}")


if __name__ == "__main__":
    main()

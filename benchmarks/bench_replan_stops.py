"""Replanning from states read off a plan in the approach to each of its stops.

Usage::

    python benchmarks/bench_replan_stops.py --paths 40 --seed 1
    PYTHONPATH=/path/to/other/checkout python benchmarks/bench_replan_stops.py --seed 1

A controller replans from the state its plan gives it; the last seconds before a stop (the
path's end, a cusp, a curvature jump with lateral-jerk limits) are where that state lies on
the max-jerk stop within the law's rounding. Random paths whose size spans decades (2–300 m),
a third each: G2 waypoint paths with plain limits, the same with comfort limits
(``j_lat_max``, ``yaw_rate_max``), and polylines with rounded corners and comfort limits (a
stop at every corner); limits from a slow forklift to a road vehicle (`bench_comfort`'s
draws). From each stop, states ``f a_max / j_max`` seconds before it (``f`` from 3 to 0.02)
are read off the plan and the rest of the path is planned from them (``path.sub(s)``,
``v0``, ``a0``). Printed: the states, the errors by class, the plans that warned, and those
whose arrival ``t + duration`` is off the original's by more than 1e-4 of its duration;
``--verbose`` lists each, and every replan over 1 s. A remaining path shorter than
``1e-9 v_max² / a_max`` is refused by design (``InvalidInputError``: no motion to plan) and
counted apart.
"""

from __future__ import annotations

import argparse
import collections
import sys
import time
import warnings
from pathlib import Path as FsPath

import numpy as np
from bench_comfort import draw_g2_case  # the same random G2 draws

import speedplan as sp

#: Seconds before each stop, in units of ``a_max / j_max`` (the length of a jerk phase).
BEFORE = (3.0, 2.0, 1.5, 1.0, 0.6, 0.3, 0.1, 0.02)
#: Arrival off the original's by more than this fraction of its duration is reported.
TARGET = 1e-4


def draw(rng: np.random.Generator, k: int) -> tuple[sp.Path, sp.Limits] | None:
    """Path and limits of draw ``k`` (a third each: plain G2, comfort G2, comfort polyline)."""
    case = draw_g2_case(rng, (2.0, 300.0))
    if case is None:
        return None
    path, plain, comfort = case
    kind = k % 3
    if kind == 2:
        pts = np.cumsum(rng.uniform(-1, 1, size=(int(rng.integers(3, 6)), 2)), axis=0)
        pts *= float(10 ** rng.uniform(0.3, 2.3))
        try:
            path = sp.Path.from_waypoints(
                pts, kind="polyline", corner_radius=float(np.linalg.norm(pts[1] - pts[0])) * 0.2)
        except sp.InvalidInputError:
            return None
    return path, sp.Limits(**plain, **(comfort if kind else {}))


def stop_times(profile: sp.SpeedProfile, v_max: float) -> list[float]:
    """When ``profile`` stops: its end and every local minimum of the speed near 0."""
    t = np.linspace(0.0, profile.duration, 40_001)
    v = np.asarray(profile.at(t).v)
    inner = (v[1:-1] <= v[:-2]) & (v[1:-1] < v[2:]) & (v[1:-1] < 1e-3 * v_max)
    return [profile.duration, *(float(x) for x in t[1:-1][inner])]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--paths", type=int, default=40)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args()
    from speedplan.core.jit import compile_families

    compile_families()
    print(f"speedplan from {FsPath(sp.__file__).parent}")
    rng = np.random.default_rng(args.seed)
    states = too_short = 0
    errors: collections.Counter[str] = collections.Counter()
    warned, off, seconds = [], [], []
    drawn = 0
    while drawn < args.paths:
        case = draw(rng, drawn)
        if case is None:
            continue
        drawn += 1
        path, lim = case
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                first = sp.plan(path, lim)
        except sp.SpeedplanError:
            continue
        for stop in stop_times(first, lim.v_max):
            for f in BEFORE:
                t = stop - f * lim.a_max / lim.j_max
                q = first.at(t)
                s0, v0, a0 = float(q.s[0]), float(q.v[0]), float(q.a[0])
                if t <= 0 or v0 <= 0 or s0 >= float(path.length) * (1 - 1e-9):
                    continue
                states += 1
                where = f"path {drawn}, stop at {stop:.3f} s, {f} a_max/j_max before"
                start = time.perf_counter()
                try:
                    with warnings.catch_warnings(record=True) as seen:
                        warnings.simplefilter("always")
                        again = sp.plan(path.sub(s0), lim, v0=v0, a0=a0)
                except sp.InvalidInputError as exc:
                    too_short += "no motion to plan" in str(exc)
                    if "no motion to plan" not in str(exc):
                        errors["InvalidInputError"] += 1
                    continue
                except sp.SpeedplanError as exc:
                    errors[type(exc).__name__] += 1
                    if args.verbose:
                        print(f"  {where}: {type(exc).__name__}: {str(exc)[:160]}")
                    continue
                finally:
                    seconds.append(time.perf_counter() - start)
                    if args.verbose and seconds[-1] > 1.0:
                        print(f"  {where}: {seconds[-1]:.2f} s")
                told = [w for w in seen if "curvature jumps" not in str(w.message)]
                if told:
                    warned.append(where)
                    if args.verbose:
                        print(f"  {where}: warned: {str(told[0].message)[:160]}")
                dev = (t + again.duration) / first.duration - 1.0
                if abs(dev) > TARGET:
                    off.append(dev)
                    if args.verbose:
                        print(f"  {where}: arrival {dev:+.1e} ({again.status})")
    sec = np.array(seconds)
    print(f"seed {args.seed}: {drawn} paths, {states} states read off their plans before stops")
    print(f"  errors: {sum(errors.values())} ({dict(errors) or 'none'}); remaining path "
          f"shorter than 1e-9 v_max²/a_max (refused by design): {too_short}")
    print(f"  warned: {len(warned)}; arrival off by more than {TARGET:.0e}: {len(off)}"
          + (f" (from {min(off):+.1e} to {max(off):+.1e})" if off else ""))
    print(f"  seconds per replan: median {np.median(sec):.3f}, 99 % "
          f"{np.quantile(sec, 0.99):.3f}, max {sec.max():.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

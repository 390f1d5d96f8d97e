"""Random waypoint paths with random slow zones, millimetres to kilometres, judged by physics.

Usage::

    python benchmarks/fuzz_zones.py --plans 150 --seed 1
    python benchmarks/fuzz_zones.py --seed 1 --case 115     # one case, with its data

Each case: 2-7 waypoints with steps of 1 cm to 1 km (``Path.from_waypoints``, G2), 0-3
square zones centred on the path (side 3 %-200 % of the step, ``v_max`` 0.03-3 m/s),
``v_max`` 0.1-30 m/s, ``a_max`` 0.1-5 m/s², ``a_lat_max`` 0.3-5 m/s², and half of the cases
without a jerk limit (else ``j_max`` 0.05-10 m/s³), on the default grid. Each plan is
sampled in time and finite-differenced (``tests/oracles.py``: ``measure``,
``within_promise``); without a jerk limit its duration is compared with a lower bound of the
exact continuous optimum (``no_jerk_lower_bound`` on each stretch between reversals, where
the vehicle stops): below it is a failure; ratios to the sampled optimum above 1.05 are
listed. Prints every
error, ``limits_exceeded`` and silent violation with its case.
"""

from __future__ import annotations

import argparse
import itertools
import math
import sys
import time
import warnings
from pathlib import Path as FsPath
from typing import Any

import numpy as np

import speedplan as sp
from speedplan.geometry import SpeedBound

sys.path.insert(0, str(FsPath(__file__).resolve().parents[1] / "tests"))
from oracles import measure, no_jerk_lower_bound, within_promise


def cases(seed: int, count: int) -> Any:
    """``(k, path, zones, limits)`` for the first ``count`` draws (paths that build only)."""
    rng = np.random.default_rng(seed)
    for k in range(count):
        scale = 10 ** rng.uniform(-2, 3)
        wps = np.cumsum(rng.normal(size=(int(rng.integers(2, 8)), 2)) * scale, axis=0)
        try:
            path = sp.Path.from_waypoints(wps)
        except sp.InvalidInputError:
            continue
        zones = []
        for _ in range(int(rng.integers(0, 4))):
            c = path.point(rng.uniform(0, path.length))
            r = scale * 10 ** rng.uniform(-1.5, 0)
            square = [(c[0] - r, c[1] - r), (c[0] + r, c[1] - r), (c[0] + r, c[1] + r),
                      (c[0] - r, c[1] + r)]
            zones.append(sp.SpeedZone(square, v_max=10 ** rng.uniform(-1.5, 0.5)))
        v_max = 10 ** rng.uniform(-1, 1.5)
        j_max = math.inf if rng.random() < 0.5 else 10 ** rng.uniform(-1.3, 1)
        lim = sp.Limits(v_max=v_max, a_max=10 ** rng.uniform(-1, 0.7),
                        a_lat_max=10 ** rng.uniform(-0.5, 0.7), j_max=j_max)
        yield k, path, zones, lim


def no_jerk_optimum(path: sp.Path, zones: list[sp.SpeedZone],
                    lim: sp.Limits) -> tuple[float, float]:
    """Lower bound and estimate of the no-jerk optimum, rest to rest between reversals.

    The vehicle stops where the travel direction flips (a cusp of the path's pieces). The
    lower bound (``no_jerk_lower_bound``) lets ``w`` rise between its samples as steeply as
    the acceleration allows, which is loose where ``w`` is small against ``2 a_max h`` (slow
    zones on long paths); the estimate integrates ``1 / v`` of the same sampled optimum by
    the trapezoidal rule (not a bound, but close on a fine sampling).
    """
    bound = SpeedBound(path, lim, zones or None)
    cuts = [0.0] + [float(path.offsets[i]) for i in range(1, len(path.pieces))
                    if path.pieces[i].direction != path.pieces[i - 1].direction] + [path.length]
    lower = estimate = 0.0
    for a, b in itertools.pairwise(cuts):
        low, s, w = no_jerk_lower_bound(bound.at_offset(a), b - a, lim.a_max, lim.a_decel,
                                        samples=200_001)
        v = np.sqrt(w)
        lower += low
        estimate += float(np.sum(2.0 * np.diff(s) / np.maximum(v[1:] + v[:-1], 1e-300)))
    return lower, estimate


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plans", type=int, default=150)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--case", type=int, default=None, help="run case K only, and show it")
    args = ap.parse_args()
    count = args.plans if args.case is None else args.case + 1
    stats = {"ok": 0, "refused": 0, "error": 0, "limits_exceeded": 0, "silent": 0,
             "below_optimum": 0}
    ratios = []
    t0 = time.perf_counter()
    for k, path, zones, lim in cases(args.seed, count):
        if args.case is not None and k != args.case:
            continue
        case = f"case {k}: L={path.length:.4g} m, {len(zones)} zones, {lim}"
        if args.case is not None:
            print(case, [(z.polygon.bounds, z.v_max) for z in zones])
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                prof = sp.plan(path, lim, zones=zones or None)
        except (sp.InfeasibleError, sp.InvalidInputError) as exc:
            stats["refused"] += 1
            print("refused:", case, exc)
            continue
        except Exception as exc:  # reported, never hidden
            stats["error"] += 1
            print(f"error {type(exc).__name__}:", case, str(exc)[:200])
            continue
        if prof.status == "limits_exceeded":
            stats["limits_exceeded"] += 1
            print("limits_exceeded:", case, prof.verification and prof.verification.violations)
            continue
        if not within_promise(measure(prof)):
            stats["silent"] += 1
            print("silent:", case)
            continue
        if math.isinf(lim.j_max):
            lower, estimate = no_jerk_optimum(path, zones, lim)
            ratio = prof.duration / estimate
            ratios.append(ratio)
            if prof.duration < lower * (1.0 - 1e-9):
                stats["below_optimum"] += 1
                print("below the optimum:", case, prof.duration / lower)
                continue
            if ratio > 1.05:
                print(f"no jerk limit, {ratio:.4f}x the sampled optimum:", case)
        stats["ok"] += 1
    print(stats, f"{time.perf_counter() - t0:.0f} s")
    if ratios:
        print(f"no jerk limit, duration / sampled optimum over {len(ratios)}: "
              f"min {min(ratios):.6f}, median {float(np.median(ratios)):.6f}, "
              f"max {max(ratios):.6f}")


if __name__ == "__main__":
    main()

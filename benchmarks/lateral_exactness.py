"""How often the relaxation stays exact with lateral-jerk (and yaw-rate) rows.

Usage::

    python benchmarks/lateral_exactness.py [--cases 200] [--seed 0]

Part 1: every bundled sample path (``paths/``) with the LGV limits (road limits for the road
file) and comfort limits ``j_lat_max`` in {1.0, 0.3} m/s³, ``yaw_rate_max`` 0.4 rad/s: status,
whether the relaxation was exact, the certified gap, the duration cost against the plain limits
and whether ``verify()`` holds. Part 2: a fuzz of random G2 waypoint paths (4–8 waypoints in
a 40 m square, deviations 0.1–1 m) with random limits (``j_lat_max`` 0.05–3 m/s³, ``yaw_rate_max``
0.2–2 rad/s or none): the share of exact relaxations, the gap quantiles, verification failures
and the seconds each `plan()` took.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import speedplan as sp
from speedplan.io import read_path, read_zones

PATHS = Path(__file__).resolve().parents[1] / "paths"
LGV = dict(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)
ROAD = dict(v_max=15.0, a_max=2.0, a_lat_max=3.0, j_max=1.0)


def sample_paths() -> None:
    print("sample path            j_lat  status    exact  gap       cost     verify")
    for f in sorted(PATHS.glob("*.*")):
        if f.suffix not in (".json", ".csv") or f.parent.name == "orders":
            continue
        base = ROAD if "road" in f.name else LGV
        path, zones = read_path(f), read_zones(f) or None
        plain = sp.plan(path, sp.Limits(**base), zones=zones)
        for j_lat in (1.0, 0.3):
            lim = sp.Limits(**base, j_lat_max=j_lat, yaw_rate_max=0.4)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                prof = sp.plan(path, lim, zones=zones)
            print(f"{f.name:22s} {j_lat:5.1f}  {prof.status:9s} {prof.exact!s:5s}  "
                  f"{prof.gap:8.2e}  {prof.duration / plain.duration - 1:+7.1%}  "
                  f"{prof.verification.ok}")


def fuzz(cases: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    exact = refined = flagged = failed = 0
    gaps, seconds = [], []
    for _ in range(cases):
        k = int(rng.integers(4, 9))
        pts = np.cumsum(rng.uniform(-10, 10, size=(k, 2)), axis=0)
        try:
            path = sp.Path.from_waypoints(pts, max_deviation=float(rng.uniform(0.1, 1.0)))
        except sp.InvalidInputError:
            continue
        lim = sp.Limits(**LGV, j_lat_max=float(np.exp(rng.uniform(np.log(0.05), np.log(3)))),
                        yaw_rate_max=None if rng.random() < 0.3 else float(rng.uniform(0.2, 2)))
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                start = time.perf_counter()
                prof = sp.plan(path, lim)
                seconds.append(time.perf_counter() - start)
        except sp.SpeedplanError as exc:
            failed += 1
            print(f"  error: {type(exc).__name__}: {exc}"[:160])
            continue
        exact += prof.exact
        refined += prof.status == "refined"
        flagged += prof.status == "limits_exceeded"
        gaps.append(prof.gap)
    done = len(gaps)
    q = np.quantile(gaps, [0.5, 0.9, 1.0]) if gaps else [np.nan] * 3
    print(f"fuzz: {done} planned, {failed} errors; exact {exact}/{done} "
          f"({exact / max(done, 1):.0%}), refined {refined}, limits_exceeded {flagged}; "
          f"gap median {q[0]:.2e}, 90% {q[1]:.2e}, max {q[2]:.2e}")
    if seconds:
        sec = np.quantile(seconds, [0.5, 0.9, 1.0])
        print(f"seconds per plan(): median {sec[0]:.2f}, 90% {sec[1]:.2f}, max {sec[2]:.2f}; "
              f"over 2 s: {sum(x > 2.0 for x in seconds)} of {len(seconds)}")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    sample_paths()
    fuzz(args.cases, args.seed)
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Hairpins on long straights, millimetres to kilometres, judged by physics.

Usage::

    python benchmarks/fuzz_dips.py --plans 80 --seed 1

Each case: a line, an arc (radius 1 mm - 1 m, 0.2 - 2.5 rad) and a line, 10 m - 5 km in all,
the arc anywhere between 5 % and 95 % of the way; ``v_max`` 0.1-30 m/s, ``a_max`` 0.1-5 m/s²,
``a_lat_max`` 0.3-5 m/s², and 30 % of the cases without a jerk limit (else ``j_max``
0.05-10 m/s³), on the default grid. The arc is a dip of the speed bound far narrower than
the grids' first look at the path (``tests/model/test_default_grid.py``). Each plan is judged
by the speed sampled on the arc (400 001 samples in time; at most ``√(a_lat_max r)``), by
finite differences (``tests/oracles.py``: ``measure``, ``within_promise``), and against the
exact no-jerk lower bound. Prints every error, ``limits_exceeded`` and silent violation.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path as FsPath

import numpy as np

import speedplan as sp
from speedplan.geometry import Arc, Line, SpeedBound

sys.path.insert(0, str(FsPath(__file__).resolve().parents[1] / "tests"))
from oracles import measure, no_jerk_lower_bound, within_promise


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plans", type=int, default=80)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    stats: dict[str, int] = {}
    t0 = time.perf_counter()
    for k in range(args.plans):
        length = 10 ** rng.uniform(1, 3.7)
        before = rng.uniform(0.05, 0.95) * length
        radius, angle = 10 ** rng.uniform(-3, 0), rng.uniform(0.2, 2.5)
        lim = sp.Limits(v_max=10 ** rng.uniform(-1, 1.5), a_max=10 ** rng.uniform(-1, 0.7),
                        a_lat_max=10 ** rng.uniform(-0.5, 0.7),
                        j_max=np.inf if rng.random() < 0.3 else 10 ** rng.uniform(-1.3, 1))
        path = sp.Path.from_segments([Line(before), Arc(radius=radius, angle=angle),
                                      Line(length - before)])
        case = f"case {k}: L={length:.4g} m, arc at {before:.4g} m, r={radius:.3g} m, {lim}"
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                prof = sp.plan(path, lim)
        except Exception as exc:  # reported, never hidden
            stats["error"] = stats.get("error", 0) + 1
            print(f"error {type(exc).__name__}:", case, str(exc)[:200])
            continue
        if prof.status == "limits_exceeded":
            stats["limits_exceeded"] = stats.get("limits_exceeded", 0) + 1
            print("limits_exceeded:", case, prof.verification and prof.verification.violations)
            continue
        traj = prof.at(np.linspace(0.0, prof.duration, 400_001))
        on_arc = (traj.s >= before) & (traj.s <= before + radius * angle)
        v_arc = min(float(np.sqrt(lim.a_lat_max * radius)), lim.v_max)
        lower = no_jerk_lower_bound(SpeedBound(path, lim), path.length, lim.a_max,
                                    lim.a_decel)[0]
        fast = bool(on_arc.any() and traj.v[on_arc].max() > v_arc * (1 + 1e-3))
        if fast or prof.duration < lower * (1 - 1e-9) or not within_promise(measure(prof)):
            stats["silent"] = stats.get("silent", 0) + 1
            print("silent:", case, "too fast on the arc" if fast else "")
            continue
        stats["ok"] = stats.get("ok", 0) + 1
    print(stats, f"{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()

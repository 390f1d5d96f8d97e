"""The jerk reversals a comfort-limited optimum has where it leaves an arc's speed bound.

Usage::

    python benchmarks/bound_kink_dip.py [--seed 1] [--draw 3] [--factors 1 2 4]

Plans one random G2 comfort case of `bench_comfort.draw_g2_case` (the ``--draw``-th of seed
``--seed``; the default is a 24.6 m path whose first corner is held at its yaw-rate bound
along the arc) on the default grid and on the same grid with every cell cut into 2 and 4
(``--factors``). For every exit of an arc (a piece join where the curvature rate turns from 0
to nonzero) it prints, over the 0.15 s before the exit, the least acceleration and how far
the speed falls below the speed at the exit's node, with the acceleration at the exit; then
the duration, the jerk sign reversals per corner (as `bench_comfort.py` counts them) and
those of the same path without comfort limits. A dip that stays the same on finer grids is
the optimum's own, not the grid's.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np

import speedplan as sp

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from bench_comfort import draw_g2_case
from oracles import corner_reversals, subdivided_default_grids

WINDOW = 0.15


def drawn_case(seed: int, index: int) -> tuple[sp.Path, dict[str, float], dict[str, float | None]]:
    rng = np.random.default_rng(seed)
    drawn = 0
    while True:
        case = draw_g2_case(rng, (5.0, 500.0))
        if case is None:
            continue
        if drawn == index:
            return case
        drawn += 1


def arc_exits(path: sp.Path) -> list[float]:
    joins = np.asarray(path.offsets)[1:-1]
    before = np.asarray(path.curvature_rate(joins - 1e-9))
    after = np.asarray(path.curvature_rate(joins + 1e-9))
    bent = np.abs(np.asarray(path.curvature(joins))) > 0
    return [float(s) for s, b, a, k in zip(joins, before, after, bent, strict=True)
            if k and b == 0.0 and a != 0.0]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--draw", type=int, default=3)
    ap.add_argument("--factors", type=int, nargs="+", default=[1, 2, 4])
    args = ap.parse_args()
    path, plain, comfort = drawn_case(args.seed, args.draw)
    lim = sp.Limits(**plain, **comfort)
    print(f"path {path.length:.2f} m; {lim}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        base = sp.plan(path, sp.Limits(**plain))
    exits = arc_exits(path)
    for k in args.factors:
        with warnings.catch_warnings(), subdivided_default_grids(k):
            warnings.simplefilter("ignore")
            prof = sp.plan(path, lim)
        print(f"grid x{k}: {len(prof.s)} nodes, {prof.status}, duration {prof.duration:.9f} s")
        for s_exit in exits:
            t_exit = float(prof.law.time_at(np.array([s_exit]))[0])
            t = np.linspace(t_exit - WINDOW, t_exit, 3001)
            _, _, v, a, _ = prof.law.state_at(t)
            print(f"  arc exit at s={s_exit:.3f} m: least a {a.min():+.4f} m/s², speed down to "
                  f"{v[-1] - v.min():.2e} m/s below the exit's, a at the exit {a[-1]:+.4f} m/s²")
        print("  jerk reversals per corner:", corner_reversals(prof.sample(0.01), lim.j_max),
              "without comfort limits:", corner_reversals(base.sample(0.01), lim.j_max))
    return 0


if __name__ == "__main__":
    sys.exit(main())

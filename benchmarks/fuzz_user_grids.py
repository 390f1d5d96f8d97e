"""Random straight moves on user grids (``plan(..., n=...)``) against ruckig and physics.

Usage::

    python benchmarks/fuzz_user_grids.py --plans 200 --seed 1

Each move: a length from 10 cm to 3 km, ``v_max`` 0.1-30 m/s, ``a_max`` 0.1-5 m/s²,
``j_max`` 0.05-10 m/s³ (log-uniform), ``n`` from 50 to 2 000 nodes, a start at rest (30 %)
or moving with any feasible-looking acceleration, an end at rest. Prints how the plans ended
— ``optimal`` / ``refined`` (then sampled in time and finite-differenced against the
tolerances the README promises, ``silent`` when they are exceeded without a warning),
``limits_exceeded``, refused (``InfeasibleError`` / ``InvalidInputError``, split by whether
ruckig finds a motion), an error — and the planned duration over ruckig's optimum.
"""

from __future__ import annotations

import argparse
import collections
import sys
import warnings
from pathlib import Path as FsPath

import numpy as np

import speedplan as sp
from speedplan.geometry import Line

sys.path.insert(0, str(FsPath(__file__).resolve().parents[1] / "tests"))
from oracles import measure, ruckig_move, within_promise


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plans", type=int, default=200)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    outcomes: collections.Counter[str] = collections.Counter()
    ratios = []
    for _ in range(args.plans):
        length = 10 ** rng.uniform(-1, 3.5)
        lim = sp.Limits(v_max=10 ** rng.uniform(-1, 1.5), a_max=10 ** rng.uniform(-1, 0.7),
                        a_lat_max=1.0, j_max=10 ** rng.uniform(-1.3, 1))
        n = int(10 ** rng.uniform(1.7, 3.3))
        v0 = rng.uniform(0, lim.v_max) if rng.random() < 0.7 else 0.0
        a0 = rng.uniform(-lim.a_max, lim.a_max) if v0 > 0 else 0.0
        optimum = ruckig_move(length, lim, v0=v0, a0=a0).duration
        case = (f"L={length:.4g} v_max={lim.v_max:.3g} a_max={lim.a_max:.3g} "
                f"j_max={lim.j_max:.3g} n={n} v0={v0:.3g} a0={a0:.3g}")
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                profile = sp.plan(sp.Path.from_segments([Line(length)]), lim, n=n, v0=v0, a0=a0)
        except (sp.InfeasibleError, sp.InvalidInputError) as exc:
            verdict = "ruckig moves it" if optimum is not None else "ruckig: no motion"
            outcomes[f"refused ({type(exc).__name__}; {verdict})"] += 1
            continue
        except Exception as exc:  # reported, never hidden
            outcomes[f"error {type(exc).__name__}"] += 1
            print("error:", case, exc)
            continue
        if profile.status == "limits_exceeded":
            outcomes["limits_exceeded"] += 1
            print("limits_exceeded:", case, profile.verification.violations)
            continue
        if not within_promise(measure(profile)):
            outcomes["silent"] += 1
            print("silent:", case)
            continue
        outcomes[profile.status] += 1
        if optimum is not None:
            ratios.append(profile.duration / optimum)
    print(dict(sorted(outcomes.items())))
    if ratios:
        print(f"duration / ruckig over {len(ratios)} plans: min {min(ratios):.6f}, "
              f"median {float(np.median(ratios)):.6f}, max {max(ratios):.6f}")


if __name__ == "__main__":
    main()

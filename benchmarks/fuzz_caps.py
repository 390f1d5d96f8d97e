"""Straight moves capped far below ``v_max`` by a span, ``v_limit`` or a zone, against ruckig.

The cap holds over the whole move, so the exact optimum is ruckig's motion with ``v_max``
set to the cap. Lengths 0.5 m-3 km (log-uniform), caps 0.03-1 m/s, ``v_max`` 3-100 times
the cap, ``a_max`` 0.1-5 m/s², ``j_max`` 0.02-5 m/s³; each move on the default grid and, with
``--n``, on a uniform grid of that many nodes. Prints every plan outside
``[1 - 1e-4, 1 + 1e-4]`` of ruckig or beyond the README's tolerances (finite differences of
the sampled trajectory, ``tests/oracles.measure``), then the range of the ratios.

    python benchmarks/fuzz_caps.py --seed 0 --moves 30
    python benchmarks/fuzz_caps.py --seed 0 --moves 30 --n 300
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path as FsPath

import numpy as np
from shapely.geometry import box

import speedplan as sp

sys.path.insert(0, str(FsPath(__file__).resolve().parents[1] / "tests"))
from oracles import measure, ruckig_duration, within_promise


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--moves", type=int, default=30)
    ap.add_argument("--n", type=int, default=None, help="a uniform grid of n nodes")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(args.seed)

    def log_uniform(lo: float, hi: float) -> float:
        return float(np.exp(rng.uniform(np.log(lo), np.log(hi))))

    ratios: list[tuple[float, int, str]] = []
    flagged = 0
    for i in range(args.moves):
        length, cap = log_uniform(0.5, 3000.0), log_uniform(0.03, 1.0)
        v_max, a, j = cap * log_uniform(3.0, 100.0), log_uniform(0.1, 5.0), log_uniform(0.02, 5.0)
        lim = sp.Limits(v_max=v_max, a_max=a, a_lat_max=1.0, j_max=j)
        exact = ruckig_duration(length, sp.Limits(v_max=cap, a_max=a, a_lat_max=1.0, j_max=j))
        path = sp.Path.from_waypoints([[0.0, 0.0], [length, 0.0]], kind="polyline")
        caps = {"span": {"spans": [sp.SpanLimit(0.0, length, v_max=cap)]},
                "v_limit": {"v_limit": ([0.0, length], [cap, cap])},
                "zone": {"zones": [sp.SpeedZone(box(-1.0, -1.0, length + 1.0, 1.0), cap)]}}
        for how, kw in caps.items():
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                profile = sp.plan(path, lim, n=args.n, **kw)
            ratio = profile.duration / exact
            ratios.append((ratio, i, how))
            m = measure(profile, samples=12_000)
            ok = within_promise(m) and profile.status in ("optimal", "refined")
            flagged += profile.status == "limits_exceeded"
            if not ok or abs(ratio - 1.0) > 1e-4:
                print(f"move {i} {how}: length {length:.4g} m, cap {cap:.4g} m/s, v_max "
                      f"{v_max:.4g}, a_max {a:.4g}, j_max {j:.4g}: {profile.status}, "
                      f"duration / ruckig {ratio:.7f}, measured {m}")
    ratios.sort()
    print(f"{len(ratios)} plans ({args.moves} moves x span, v_limit, zone; "
          f"{'default grid' if args.n is None else f'n = {args.n}'}), {flagged} flagged; "
          f"duration / ruckig at the cap in [{ratios[0][0]:.8f}, {ratios[-1][0]:.8f}]")


if __name__ == "__main__":
    main()

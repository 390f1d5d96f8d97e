"""Comfort limits in curves: status, certified gap, jerk chatter, accuracy and time per plan.

Usage::

    python benchmarks/bench_comfort.py [--plans 200] [--seed 0] [--fine 40]

Part 1 plans every bundled sample path (``paths/``, LGV limits; road limits for the road file)
with comfort limits ``j_lat_max = 0.3 j_max``-ish and ``yaw_rate_max``; part 2 plans ``--plans``
random G2 waypoint paths whose size spans decades (5 m to 500 m squares) with random limits
from a slow forklift to a road vehicle (log-uniform) and comfort limits. Each plan is also made
without its comfort limits. Printed: status counts, the certified gap's quantiles, jerk sign
reversals per corner (``|j| >= 0.25 j_max`` in the trajectory's jerk column at 100 Hz) with and
without comfort limits and how many corners exceed ``2 × without + 4``, the duration against a
solve on the default grid with four times its nodes per jerk transition (``--fine`` plans),
and the seconds per ``plan()``. Run it with ``PYTHONPATH`` pointing at another checkout to
compare two versions of the library on the same draws.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import sys
import time
import warnings
from collections import Counter
from pathlib import Path

import numpy as np

import speedplan as sp
from speedplan.io import read_path, read_zones

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from oracles import corner_reversals  # the tests' count of jerk reversals per corner

PATHS = Path(__file__).resolve().parents[1] / "paths"
LGV = dict(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)
ROAD = dict(v_max=15.0, a_max=2.0, a_lat_max=3.0, j_max=1.0)
FINE_FACTOR = 4


class Tally:
    """What the plans of one part measured."""

    def __init__(self) -> None:
        self.status: Counter[str] = Counter()
        self.gaps: list[float] = []
        self.seconds: list[float] = []
        self.corners = 0
        self.chattering = 0
        self.reversals: list[int] = []
        self.reversals_plain: list[int] = []
        self.fine: list[float] = []
        self.errors: list[str] = []

    def add(self, path: sp.Path, lim: sp.Limits, zones, fine: bool) -> None:
        plain = sp.Limits(v_max=lim.v_max, a_max=lim.a_max, a_decel=lim.a_decel,
                          a_lat_max=lim.a_lat_max, j_max=lim.j_max)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                start = time.perf_counter()
                prof = sp.plan(path, lim, zones=zones)
                self.seconds.append(time.perf_counter() - start)
                base = sp.plan(path, plain, zones=zones)
        except sp.SpeedplanError as exc:
            self.errors.append(f"{type(exc).__name__}: {exc}"[:160])
            return
        self.status[prof.status] += 1
        self.gaps.append(prof.gap)
        got = corner_reversals(prof.sample(0.01), lim.j_max)
        ref = corner_reversals(base.sample(0.01), lim.j_max)
        if len(got) == len(ref):
            self.corners += len(got)
            self.chattering += sum(g > 2 * r + 4 for g, r in zip(got, ref, strict=True))
            self.reversals += got
            self.reversals_plain += ref
        if fine:
            self.fine.append(_fine_difference(path, lim, zones, prof))

    def report(self, title: str) -> None:
        done = sum(self.status.values())
        print(f"{title}: {done} planned, {len(self.errors)} errors; status "
              + ", ".join(f"{k} {v}" for k, v in sorted(self.status.items())))
        for err in self.errors[:5]:
            print(f"  {err}")
        if self.gaps:
            q = np.quantile(self.gaps, [0.5, 0.9, 1.0])
            print(f"  certified gap: median {q[0]:.2e}, 90% {q[1]:.2e}, max {q[2]:.2e}; "
                  f"over 1 %: {sum(g > 0.01 for g in self.gaps)}")
        if self.corners:
            print(f"  jerk reversals per corner: median {np.median(self.reversals):.0f}, max "
                  f"{max(self.reversals)} (without comfort limits: median "
                  f"{np.median(self.reversals_plain):.0f}, max {max(self.reversals_plain)}); "
                  f"corners over 2x+4: {self.chattering} of {self.corners}")
        if self.fine:
            d = np.asarray(self.fine)
            finite = d[np.isfinite(d)]
            if finite.size:
                print(f"  duration / four-times-finer default grid - 1 ({finite.size} plans): "
                      f"median {np.median(finite):+.2e}, min {finite.min():+.2e}, max "
                      f"{finite.max():+.2e}; |.| over 1e-4: {int(np.sum(np.abs(finite) > 1e-4))}")
        if self.seconds:
            sec = np.quantile(self.seconds, [0.5, 0.9, 1.0])
            print(f"  seconds per plan(): median {sec[0]:.3f}, 90% {sec[1]:.3f}, max "
                  f"{sec[2]:.3f}")


@contextlib.contextmanager
def _finer_default_grids(factor: float):
    """The default grids with ``factor`` times the nodes per jerk transition (and node cap).

    The reference converges with the default grid's own family: a uniform grid with as many
    nodes is far coarser in the jerk transitions (5e-4 short of the converged duration at
    twice the default grid's nodes on a corner path, measured). The planning strategy's
    coarser grids are off meanwhile, so that a stalled solve is not answered on a coarser grid.
    """
    import speedplan.model as model_pkg
    from speedplan import strategy

    grid = importlib.import_module("speedplan.model.grid")
    original = grid.adaptive_grid

    def finer(*args, **kw):
        kw["per_phase"] = grid.DEFAULT_PER_PHASE * factor
        kw["max_nodes"] = int(kw.get("max_nodes", grid.MAX_DEFAULT_NODES) * factor)
        return original(*args, **kw)

    users = [m for m in list(sys.modules.values())
             if getattr(m, "__name__", "").startswith(model_pkg.__name__)
             and getattr(m, "adaptive_grid", None) is original]
    for m in users:
        m.adaptive_grid = finer
    coarser, strategy.COARSER_GRIDS = strategy.COARSER_GRIDS, ()
    try:
        yield
    finally:
        strategy.COARSER_GRIDS = coarser
        for m in users:
            m.adaptive_grid = original


def _fine_difference(path: sp.Path, lim: sp.Limits, zones, prof: sp.SpeedProfile) -> float:
    try:
        with warnings.catch_warnings(), _finer_default_grids(FINE_FACTOR):
            warnings.simplefilter("ignore")
            fine = sp.plan(path, lim, zones=zones)
    except sp.SpeedplanError:
        return float("nan")
    return prof.duration / fine.duration - 1.0


def sample_paths(fine: bool) -> None:
    tally = Tally()
    for f in sorted(PATHS.glob("*.*")):
        if f.suffix not in (".json", ".csv"):
            continue
        base = ROAD if "road" in f.name else LGV
        lim = sp.Limits(**base, j_lat_max=0.3, yaw_rate_max=0.4)
        tally.add(read_path(f), lim, read_zones(f) or None, fine)
    tally.report("sample paths")


def _log_uniform(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(np.exp(rng.uniform(np.log(lo), np.log(hi))))


def draw_g2_case(rng: np.random.Generator, size: tuple[float, float]
                 ) -> tuple[sp.Path, dict[str, float], dict[str, float | None]] | None:
    """A random G2 waypoint path of ``size`` metres (log-uniform range) and its limits.

    ``(path, plain, comfort)``: ``Limits`` keywords without and with the comfort limits
    (``yaw_rate_max`` ``None`` in 30 % of the draws); ``None`` when the waypoints make no
    path (the caller draws again).
    """
    scale = _log_uniform(rng, *size)
    k = int(rng.integers(4, 8))
    pts = np.cumsum(rng.uniform(-scale / 2, scale / 2, size=(k, 2)), axis=0)
    try:
        path = sp.Path.from_waypoints(pts, max_deviation=scale * float(rng.uniform(0.01, 0.1)))
    except sp.InvalidInputError:
        return None
    v_max = _log_uniform(rng, 0.5, 30.0)
    j_max = _log_uniform(rng, 0.2, 5.0)
    plain = dict(v_max=v_max, a_max=_log_uniform(rng, 0.2, 3.0),
                 a_lat_max=_log_uniform(rng, 0.3, 4.0), j_max=j_max)
    comfort = dict(j_lat_max=j_max * _log_uniform(rng, 0.1, 1.0),
                   yaw_rate_max=None if rng.random() < 0.3 else _log_uniform(rng, 0.2, 2.0))
    return path, plain, comfort


def fuzz(plans: int, seed: int, fine: int) -> None:
    rng = np.random.default_rng(seed)
    tally = Tally()
    drawn = 0
    while drawn < plans:
        case = draw_g2_case(rng, (5.0, 500.0))
        if case is None:
            continue
        path, plain, comfort = case
        lim = sp.Limits(**plain, **comfort)
        tally.add(path, lim, None, drawn < fine)
        drawn += 1
    tally.report(f"random G2 comfort plans (seed {seed})")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plans", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--fine", type=int, default=40,
                    help="how many of the random plans are also solved on a finer grid")
    args = ap.parse_args()
    print(f"speedplan from {Path(sp.__file__).parent}")
    sample_paths(fine=True)
    fuzz(args.plans, args.seed, args.fine)
    return 0


if __name__ == "__main__":
    sys.exit(main())

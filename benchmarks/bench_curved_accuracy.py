"""Curved paths: the default grid's duration against the converged duration, and replanning.

Usage::

    python benchmarks/bench_curved_accuracy.py [--paths 40] [--seed 0] [--factors 2,4]
                                                [--replan 6] [--verbose]

Every bundled sample path (``paths/``, LGV limits; road limits for the road file) and
``--paths`` random curved paths (G2 corners through 4–7 random waypoints in squares of
2 m to 2 km, limits log-uniform from a slow forklift to a road vehicle) is planned with its
plain limits and with comfort limits (``j_lat_max``, ``yaw_rate_max``).

**Converged duration.** Each request is planned again on its own default grid with every
cell cut into ``k`` equal steps, for each ``k`` of ``--factors`` (the same grid family,
every node and anchor kept, the steps ``k`` times finer everywhere; the local refinement of
``plan()`` may refine further). With durations ``T_1`` (the default grid), ``T_k`` for the
largest two factors ``k1 < k2`` and the observed order ``p`` (from ``T_1``, ``T_k1``,
``T_k2``, clipped to [1, 4]), the converged duration is the Richardson extrapolation
``T_* = T_k2 + (T_k2 - T_k1) / ((k2 / k1)^p - 1)``; its own uncertainty is printed as
``|T_* - T_k2| / T_*`` ("ref ±"), which must be small against the default grid's error
``T_1 / T_* - 1`` for the comparison to mean anything.

**Replanning.** For ``--replan`` states read off each sample path's plan (``profile.at(t)``
at evenly spaced times), the rest of the path from that state is planned
(``path.sub(s)``, ``v0 = v``, ``a0 = a``): ``t + remaining duration`` against the original
duration.

Printed: per request (with ``--verbose``) and as a summary, how many default-grid durations
lie more than 1e-4 from the converged one, the largest deviation, the observed orders, and
the seconds per ``plan()`` on the default grid (wall clock, after the kernels are compiled).
Run with ``PYTHONPATH`` at another checkout to measure another version on the same draws.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import speedplan as sp
from speedplan.io import read_path, read_zones

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from oracles import subdivided_default_grids  # the tests' reference: finer default grids

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_comfort import draw_g2_case  # the same random G2 draws

PATHS = Path(__file__).resolve().parents[1] / "paths"
LGV = dict(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)
ROAD = dict(v_max=15.0, a_max=2.0, a_lat_max=3.0, j_max=1.0)
COMFORT = dict(j_lat_max=0.3, yaw_rate_max=0.4)
TARGET = 1e-4


@dataclass
class Case:
    """One request: its name, path, limits and zones."""

    name: str
    path: sp.Path
    limits: sp.Limits
    zones: list | None = None


@dataclass
class Outcome:
    """What one request measured."""

    case: Case
    status: str
    nodes: int
    seconds: float
    durations: list[float]
    converged: float
    uncertainty: float
    order: float

    @property
    def error(self) -> float:
        return self.durations[0] / self.converged - 1.0


def _plan(case: Case) -> sp.SpeedProfile:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return sp.plan(case.path, case.limits, zones=case.zones)


def measure(case: Case, factors: list[int]) -> Outcome | str:
    """The default-grid plan, the subdivided ones and the extrapolated duration."""
    try:
        start = time.perf_counter()
        prof = _plan(case)
        seconds = time.perf_counter() - start
        durations = [prof.duration]
        for k in factors:
            with subdivided_default_grids(k):
                durations.append(_plan(case).duration)
    except sp.SpeedplanError as exc:
        return f"{case.name}: {type(exc).__name__}: {exc}"[:200]
    ks = [1, *factors]
    t1, ta, tb = durations[0], durations[-2], durations[-1]
    ka, kb = ks[-2], ks[-1]
    order = 2.0
    if len(ks) >= 3 and abs(tb - ta) > 0 and abs(ta - durations[-3]) > 0:
        ratio = abs(ta - durations[-3]) / abs(tb - ta)
        order = float(np.log(ratio) / np.log(kb / ka)) if ratio > 0 else 2.0
    p = float(np.clip(order, 1.0, 4.0))
    converged = tb + (tb - ta) / ((kb / ka) ** p - 1.0)
    del t1
    return Outcome(case, prof.status, int(prof.s.size), seconds, durations, converged,
                   abs(converged - tb) / converged, order)


def sample_cases() -> list[Case]:
    out = []
    for f in sorted(PATHS.glob("*.*")):
        if f.suffix not in (".json", ".csv"):
            continue
        base = ROAD if "road" in f.name else LGV
        path, zones = read_path(f), read_zones(f) or None
        out.append(Case(f"{f.name} plain", path, sp.Limits(**base), zones))
        out.append(Case(f"{f.name} comfort", path, sp.Limits(**base, **COMFORT), zones))
    return out


def random_cases(count: int, seed: int) -> list[Case]:
    """``count`` random G2 waypoint paths, each with plain and comfort limits."""
    rng = np.random.default_rng(seed)
    out: list[Case] = []
    drawn = 0
    while drawn < count:
        case = draw_g2_case(rng, (2.0, 2000.0))
        if case is None:
            continue
        path, plain, comfort = case
        v_max = plain["v_max"]
        name = f"random {drawn:02d} ({path.length:.3g} m, v_max {v_max:.3g})"
        out.append(Case(f"{name} plain", path, sp.Limits(**plain)))
        out.append(Case(f"{name} comfort", path, sp.Limits(**plain, **comfort)))
        drawn += 1
    return out


def report(title: str, outcomes: list[Outcome], errors: list[str], verbose: bool) -> None:
    print(f"{title}: {len(outcomes)} planned, {len(errors)} errors")
    for err in errors:
        print(f"  {err}")
    if verbose:
        for o in outcomes:
            print(f"  {o.case.name:48s} {o.status:9s} n={o.nodes:<6d} default "
                  f"{o.durations[0]:.7g} s  converged {o.converged:.7g} s "
                  f"(ref ±{o.uncertainty:.1e}, order {o.order:.1f})  error {o.error:+.2e}  "
                  f"{o.seconds:.3f} s")
    for kind in ("plain", "comfort"):
        group = [o for o in outcomes if o.case.name.endswith(kind)]
        if not group:
            continue
        err = np.array([o.error for o in group])
        unc = np.array([o.uncertainty for o in group])
        sec = np.array([o.seconds for o in group])
        worst = group[int(np.argmax(np.abs(err)))]
        print(f"  {kind:7s} {len(group):3d}: |default / converged - 1| median "
              f"{np.median(np.abs(err)):.1e}, max {np.abs(err).max():.1e} ({worst.case.name}); "
              f"over {TARGET:.0e}: {int(np.sum(np.abs(err) > TARGET))}; reference ± median "
              f"{np.median(unc):.1e}, max {unc.max():.1e}; order median "
              f"{np.median([o.order for o in group]):.1f}; seconds per plan median "
              f"{np.median(sec):.3f}, max {sec.max():.3f}")


def replanning(states: int) -> None:
    """Replan the rest of each sample path from states read off its plan."""
    print(f"replanning from {states} states read off each sample path's plan "
          "(t + remaining) / duration - 1:")
    for case in sample_cases():
        first = _plan(case)
        dev = []
        for t in np.linspace(0.1, 0.9, states) * first.duration:
            state = first.at(t)
            s0 = float(state.s[0])
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    again = sp.plan(case.path.sub(s0), case.limits, zones=case.zones,
                                    v0=float(state.v[0]), a0=float(state.a[0]))
            except sp.SpeedplanError as exc:
                print(f"  {case.name}: t={t:.3f}: {type(exc).__name__}: {exc}"[:200])
                continue
            dev.append((t + again.duration) / first.duration - 1.0)
        d = np.array(dev)
        print(f"  {case.name:30s} min {d.min():+.2e} max {d.max():+.2e}; "
              f"|.| over {TARGET:.0e}: {int(np.sum(np.abs(d) > TARGET))} of {d.size}")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--paths", type=int, default=40)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--factors", default="2,4",
                    help="cell subdivisions of the reference plans, comma-separated")
    ap.add_argument("--replan", type=int, default=6,
                    help="states per sample path to replan from (0: none)")
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args()
    factors = [int(k) for k in args.factors.split(",")]
    print(f"speedplan from {Path(sp.__file__).parent}")
    from speedplan.core.jit import compile_families

    compile_families()
    for title, cases in (("sample paths", sample_cases()),
                         (f"random curved paths (seed {args.seed})",
                          random_cases(args.paths, args.seed))):
        outcomes, errors = [], []
        for case in cases:
            got = measure(case, factors)
            (errors if isinstance(got, str) else outcomes).append(got)
        report(title, outcomes, errors, args.verbose)
    if args.replan:
        replanning(args.replan)
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Very fine uniform grids: refused up front when unresolvable, solved at the finest allowed.

Straights with the LGV limits (``v_max=2, a_max=1,
a_lat_max=1, j_max=0.5``) at steps down to 0.05 mm, and the finest grid the refusal's message
suggests. Prints, per case, the outcome (status and backend, or the exception), the
relaxation's ramp length in grid steps (:func:`speedplan.solve.banded.ramp_steps`), its
certified gap and wall time.

    python benchmarks/bench_fine_grids.py
"""

from __future__ import annotations

import re
import time
import warnings

import speedplan as sp
from speedplan.geometry import Line
from speedplan.model import Leg, PlanRequest, build_model
from speedplan.solve.banded import ramp_steps

LGV = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)
CASES = [(10.0, 20000), (10.0, 30000), (10.0, 100000), (10.0, 200000), (30.0, 100000),
         (100.0, 100000)]


def run(length: float, n: int) -> str | None:
    """Plan the straight; print a line; return the suggested n when refused."""
    path = sp.Path.from_segments([Line(length)])
    legs = build_model(PlanRequest.create(path, LGV, n=n)).legs
    steps = max(ramp_steps(leg.problem) for leg in legs if isinstance(leg, Leg))
    t0 = time.perf_counter()
    suggestion = None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            prof = sp.plan(path, LGV, n=n)
            sol = prof.solution
            out = (f"{prof.status:<9} {sol.backend:<9} gap "
                   f"{(sol.objective - sol.lower_bound) / sol.objective:.1e}")
        except sp.InvalidInputError as exc:
            out = "refused: " + str(exc).split("; ")[-1]
            found = re.search(r"n <= (\d+)", str(exc))
            suggestion = found.group(1) if found else None
        except Exception as exc:  # reported, not hidden: the point of the benchmark
            out = f"{type(exc).__name__}: {exc}"
    print(f"{length:>6g} m  n={n:<7d} ramp {steps:>7.0f} steps  {out}  "
          f"{time.perf_counter() - t0:.1f} s", flush=True)
    return suggestion


def main() -> None:
    tried: set[float] = set()
    for length, n in CASES:
        suggestion = run(length, n)
        if suggestion is not None and length not in tried:  # the finest grid allowed
            tried.add(length)
            run(length, int(suggestion))


if __name__ == "__main__":
    main()

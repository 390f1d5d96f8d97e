"""Offline trust fuzz: straight moves over decades of scale against ruckig and finite differences.

Usage::

    python benchmarks/fuzz_trust.py --plans 20000 --seed 0 [--workers 2] [--samples 20000]

Prints the counts per outcome (planned, refused and why, flagged ``limits_exceeded``,
ruckig's own numerical failures) and every failure (silent violation, duration below ruckig's
optimum by more than 1e-4, false refusal or acceptance, solver error, crash) with its case.
Exits 1 if there is any failure. The cases and the checks are those of ``tests/api/test_fuzz.py``
(``tests/trust_fuzz.py``).
"""

from __future__ import annotations

import argparse
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

import numpy as np
from trust_fuzz import FAILURES, draw_case, run_case, summarise


def _run(args: tuple[int, int, int]) -> list:
    seed, count, samples = args
    rng = np.random.default_rng(seed)
    return [run_case(draw_case(rng), samples=samples) for _ in range(count)]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plans", type=int, default=20_000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--samples", type=int, default=20_000, help="time samples per plan")
    args = ap.parse_args()
    chunk = 250
    jobs = [(args.seed * 1_000_003 + i, min(chunk, args.plans - i * chunk), args.samples)
            for i in range((args.plans + chunk - 1) // chunk)]
    outcomes = []
    with ProcessPoolExecutor(args.workers) as ex:
        for part in ex.map(_run, jobs):
            outcomes.extend(part)
            print(f"\r{len(outcomes)}/{args.plans}", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    print(summarise(outcomes))
    failures = [o for o in outcomes if o.kind in FAILURES]
    for o in failures:
        print(f"FAILURE {o.kind}: {o.case.describe()}: {o.detail}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

"""Record or compare the banded kernel's outputs on a fixed set of instances, bit for bit.

The instances: the paper's 18 families x 2 seeds at n = 1000, the log-uniform-J family
(4 seeds), and the ``plan()`` grids of the sample paths in ``paths/`` (default grid and
n = 5000, every leg). Each is solved by ``solve_problem(problem, backend="banded",
refine="never")``; we keep the relaxation's ``w``, the kernel's linear-row multipliers ``yl``,
the certified lower bound, the iteration count and the status (or the exception's name).
Then ``plan()`` end to end on each sample path: its duration and the 100 Hz trajectory's speed.

    python benchmarks/kernel_fingerprint.py record /tmp/before.npz
    python benchmarks/kernel_fingerprint.py compare /tmp/before.npz /tmp/after.npz
"""

from __future__ import annotations

import argparse
import glob
import os
import warnings
from typing import Any

import numpy as np

import speedplan as sp
from speedplan.io import read_path, read_zones
from speedplan.model import Leg, PlanRequest, build_model
from speedplan.solve import _banded_ipm as ipm
from speedplan.solve.banded import compile_kernel
from speedplan.solve.discrete import solve_problem
from speedplan.solve.paper import FAMILIES, paper_instance
from speedplan.solve.problem import DiscreteProblem

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
LGV = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)
ROAD = sp.Limits(v_max=15.0, a_max=2.0, a_lat_max=3.0, j_max=1.0)


def instances() -> list[tuple[str, DiscreteProblem]]:
    out: list[tuple[str, DiscreteProblem]] = []
    for fam in FAMILIES:
        for seed in (0, 1):
            inst = paper_instance(*fam, n=1000, seed=seed)
            out.append((f"{'/'.join(fam)}:{seed}", _paper(inst)))
    for seed in range(4):
        inst = paper_instance("rnd", "cnst", "logrnd", n=1000, seed=seed)
        out.append((f"logrnd:{seed}", _paper(inst)))
    for f in _sample_paths():
        lim = ROAD if "road" in f else LGV
        for n in (None, 5000):
            req = PlanRequest.create(read_path(f), lim, zones=read_zones(f) or None, n=n)
            legs = [leg for leg in build_model(req).legs if isinstance(leg, Leg)]
            for k, leg in enumerate(legs):
                suffix = f"/{k}" if len(legs) > 1 else ""
                out.append((f"{os.path.basename(f)}:{n}{suffix}", leg.problem))
    # Rows the sample plans above never have: lateral-jerk families (two per node at the
    # joins of path pieces) and floors w_min (a moving, braking start).
    aisle = read_path(os.path.join(ROOT, "paths", "aisle_corners.csv"))
    comfort = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5, j_lat_max=0.3)
    for tag, kw in (("lateral", {}), ("lateral+moving", {"v0": 0.8, "a0": -0.2, "n": 800})):
        legs = [leg for leg in build_model(PlanRequest.create(aisle, comfort, **kw)).legs
                if isinstance(leg, Leg)]
        out += [(f"aisle_corners.csv:{tag}/{k}", leg.problem) for k, leg in enumerate(legs)]
    return out


def _sample_paths() -> list[str]:
    return sorted(glob.glob(os.path.join(ROOT, "paths", "*.csv"))
                  + glob.glob(os.path.join(ROOT, "paths", "*.json")))


def plans() -> dict[str, Any]:
    """``plan()`` end to end on the sample paths: duration, and the 100 Hz trajectory's v."""
    out: dict[str, Any] = {}
    for f in _sample_paths():
        lim = ROAD if "road" in f else LGV
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            prof = sp.plan(read_path(f), lim, zones=read_zones(f) or None)
        name = f"plan:{os.path.basename(f)}"
        out[f"{name}|duration"] = np.array(prof.duration)
        out[f"{name}|v"] = prof.sample(0.01).v
    return out


def _paper(inst: Any) -> DiscreteProblem:
    n = inst.w_max.size
    return DiscreteProblem(s=np.arange(n, dtype=float), w_max=inst.w_max, accel=inst.A,
                           decel=inst.A, jerk=inst.J)


def record(path: str) -> None:
    arrays: dict[str, Any] = {}
    captured: list[Any] = []
    real = ipm.iterate

    def spy(*args: Any) -> Any:
        out = real(*args)
        if isinstance(out[0], np.ndarray):  # the kernel before it took its arrays as Point
            captured.append((out[0].copy(), out[1].copy()))
        else:
            captured.append((args[1].w.copy(), args[1].yl.copy()))
        return out

    ipm.iterate = spy
    try:
        for name, problem in instances():
            captured.clear()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                try:
                    sol = solve_problem(problem, backend="banded", refine="never")
                except Exception as exc:  # recorded, compared like any other outcome
                    arrays[f"{name}|error"] = np.array(type(exc).__name__)
                    continue
            assert sol.relaxation is not None
            arrays[f"{name}|w"] = sol.relaxation.w
            arrays[f"{name}|lower"] = np.array(sol.lower_bound)
            arrays[f"{name}|iterations"] = np.array(sol.relaxation.iterations)
            arrays[f"{name}|status"] = np.array(sol.relaxation.status)
            arrays[f"{name}|backend"] = np.array(sol.backend)
            for k, out in enumerate(captured):
                arrays[f"{name}|yl{k}"] = out[1]
                arrays[f"{name}|wint{k}"] = out[0]
    finally:
        ipm.iterate = real
    compile_kernel()  # plan() must use the banded backend, not its fallback
    arrays.update(plans())
    np.savez(path, **arrays)
    print(f"recorded {len({k.split('|')[0] for k in arrays})} instances into {path}")


def compare(a_path: str, b_path: str) -> None:
    a, b = np.load(a_path), np.load(b_path)
    names = sorted({k.split("|")[0] for k in a.files} | {k.split("|")[0] for k in b.files})
    same = 0
    for name in names:
        ka = sorted(k for k in a.files if k.split("|")[0] == name)
        kb = sorted(k for k in b.files if k.split("|")[0] == name)
        if ka != kb:
            print(f"{name}: different outputs {ka} vs {kb}")
            continue
        diff = [k.split("|")[1] for k in ka if not np.array_equal(a[k], b[k])]
        if diff:
            w = f"{name}|w"
            rel = (float(np.max(np.abs(a[w] - b[w])) / np.max(np.abs(a[w])))
                   if w in a.files else float("nan"))
            low = f"{name}|lower"
            drel = (float(abs(a[low] - b[low]) / abs(a[low])) if low in a.files
                    else float("nan"))
            it = f"{name}|iterations"
            its = f"{a[it]}->{b[it]}" if it in a.files else ""
            print(f"{name}: differs in {diff}; max |dw|/max w {rel:.1e}, "
                  f"lower bound rel {drel:.1e}, iterations {its}")
        else:
            same += 1
    print(f"{same} of {len(names)} instances bitwise identical")


def record_or_compare(description: str, record: Any, compare: Any) -> None:
    """The command line of a ``record OUT`` / ``compare A B`` script (this one, sample_states)."""
    parser = argparse.ArgumentParser(description=description)
    sub = parser.add_subparsers(dest="cmd", required=True)
    sub.add_parser("record").add_argument("out")
    c = sub.add_parser("compare")
    c.add_argument("a")
    c.add_argument("b")
    args = parser.parse_args()
    if args.cmd == "record":
        record(args.out)
    else:
        compare(args.a, args.b)


def main() -> None:
    record_or_compare(__doc__.splitlines()[0], record, compare)


if __name__ == "__main__":
    main()

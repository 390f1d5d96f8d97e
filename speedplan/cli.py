"""Command line: ``speedplan plan``, ``speedplan demo``, ``speedplan bench``.

Exit codes: 0 success; 2 bad arguments or unreadable input; 3 infeasible request;
4 solver failure; 5 limits exceeded beyond tolerance (only with ``--strict``).
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from collections.abc import Sequence
from pathlib import Path as FsPath

import numpy as np

from .core.errors import (
    InfeasibleError,
    InvalidInputError,
    LimitWarning,
    SolverError,
    SpeedplanError,
)
from .core.limits import Limits

__all__ = ["EXIT_CODES", "main"]

EXIT_CODES = {"ok": 0, "usage": 2, "infeasible": 3, "solver": 4, "limits": 5}
DEMO_PATH = "warehouse_loop.json"


def _bundled_paths_dir() -> FsPath:
    """The sample paths: inside the installed package, or the repository's ``paths/``."""
    here = FsPath(__file__).resolve().parent
    for candidate in (here / "paths", here.parent / "paths"):
        if candidate.is_dir():
            return candidate
    raise InvalidInputError("the bundled sample paths were not found; reinstall speedplan")


def _add_limits(p: argparse.ArgumentParser, defaults: dict[str, float] | None = None) -> None:
    d = defaults or {}
    g = p.add_argument_group("limits (SI units)")
    for flag, help_ in (("v-max", "speed limit [m/s]"), ("a-max", "acceleration limit [m/s²]"),
                        ("a-lat-max", "lateral acceleration limit [m/s²]"),
                        ("j-max", "jerk limit [m/s³]")):
        key = flag.replace("-", "_")
        g.add_argument(f"--{flag}", type=float, required=key not in d, default=d.get(key),
                       help=help_)
    g.add_argument("--a-decel", type=float, default=None,
                   help="braking limit [m/s²] (default a-max)")


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        prog="speedplan",
        description="Minimum-time speed planning along a path under speed, acceleration, "
        "lateral-acceleration and jerk limits.",
        epilog="exit codes: 0 ok, 2 bad input, 3 infeasible, 4 solver failure, "
        "5 limits exceeded (--strict)",
    )
    sub = ap.add_subparsers(dest="command", required=True)
    p = sub.add_parser("plan", help="plan a path file (CSV waypoints, JSON segments, VDA 5050)")
    p.add_argument("pathfile", help="path file: .csv waypoints, .json segments or VDA 5050 NURBS")
    _add_limits(p)
    _add_common(p)
    d = sub.add_parser("demo", help="plan the bundled warehouse loop; write a trajectory and plot")
    _add_limits(d, {"v_max": 2.0, "a_max": 1.0, "a_lat_max": 1.0, "j_max": 0.5})
    _add_common(d, out="speedplan-demo.csv", plot="speedplan-demo.png")
    b = sub.add_parser("bench", help="benchmark the solver on the paper's instance families")
    b.add_argument("--instances", type=int, default=3, help="instances per family")
    b.add_argument("--n", type=int, default=1000, help="grid size")
    return ap


def _add_common(p: argparse.ArgumentParser, out: str | None = None,
                plot: str | None = None) -> None:
    p.add_argument("--v0", type=float, default=0.0, help="start speed [m/s]")
    p.add_argument("--a0", type=float, default=0.0, help="start acceleration [m/s²]")
    p.add_argument("--vf", type=float, default=0.0, help="end speed [m/s]")
    p.add_argument("--af", type=float, default=0.0, help="end acceleration [m/s²]")
    p.add_argument("--n", type=int, default=None, help="uniform grid with N nodes")
    p.add_argument("--ds", type=float, default=None, help="uniform grid step [m]")
    p.add_argument("--dt", type=float, default=0.01, help="trajectory sampling period [s]")
    p.add_argument("--standstill", choices=("smooth", "free"), default="smooth")
    p.add_argument("-o", "--output", default=out,
                   help="trajectory file (.csv or .json)" + (f"; default {out}" if out else ""))
    p.add_argument("--plot", default=plot, help="figure file (.png, .svg, .pdf)")
    p.add_argument("--strict", action="store_true", help="exit 5 if a limit is exceeded")


def _run_plan(args: argparse.Namespace, pathfile: FsPath) -> int:
    from .io import read_path, read_zones
    from .plan import plan

    path = read_path(pathfile)
    zones = read_zones(pathfile)
    limits = Limits(v_max=args.v_max, a_max=args.a_max, a_lat_max=args.a_lat_max,
                    j_max=args.j_max, a_decel=args.a_decel)
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", LimitWarning)
        profile = plan(path, limits, n=args.n, ds=args.ds, v0=args.v0, a0=args.a0, vf=args.vf,
                       af=args.af, zones=zones or None, standstill=args.standstill)
    elapsed = time.perf_counter() - t0
    check = profile.verification or profile.verify()
    print(f"path      {pathfile.name}: {path.length:.3f} m, {profile.s.size} grid nodes")
    print(f"duration  {profile.duration:.4f} s   (planned in {elapsed:.3f} s)")
    print(f"status    {profile.status}   exact={profile.exact}   gap={profile.gap:.2e}")
    print("realised maxima / limits:")
    print("  " + check.summary().replace("\n", "\n  "))
    if args.output:
        traj = profile.sample(args.dt)
        out = FsPath(args.output)
        if out.suffix.lower() == ".json":
            traj.to_json(out)
        else:
            traj.to_csv(out)
        print(f"wrote     {out} ({len(traj)} samples every {args.dt} s)")
    if args.plot:
        from .plot import plot_profile

        plot_profile(profile, args.plot, dt=args.dt)
        print(f"wrote     {args.plot}")
    for w in caught:
        print(f"warning: {w.message}", file=sys.stderr)
    if args.strict and not check.ok:
        return EXIT_CODES["limits"]
    return EXIT_CODES["ok"]


def _run_bench(args: argparse.Namespace) -> int:
    from .solve import solve_discrete
    from .solve.paper import FAMILIES, paper_instance

    print(f"{'W':8s} {'A':5s} {'J':5s} {'non-exact':>9s} {'median time [s]':>16s}")
    for i, fam in enumerate(FAMILIES):
        times, non_exact = [], 0
        for k in range(args.instances):
            inst = paper_instance(*fam, n=args.n, seed=1000 * i + k)
            sol = solve_discrete(inst.w_max, inst.A, inst.J)
            times.append(sol.relaxation.time if sol.relaxation else 0.0)
            non_exact += not sol.exact
        print(f"{fam[0]:8s} {fam[1]:5s} {fam[2]:5s} {non_exact:>5d}/{args.instances:<3d} "
              f"{float(np.median(times)):16.4f}   [{i + 1}/{len(FAMILIES)}]", flush=True)
    return EXIT_CODES["ok"]


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``speedplan`` command; returns the exit code."""
    args = _parser().parse_args(argv)
    try:
        if args.command == "plan":
            return _run_plan(args, FsPath(args.pathfile))
        if args.command == "demo":
            return _run_plan(args, _bundled_paths_dir() / DEMO_PATH)
        return _run_bench(args)
    except InfeasibleError as exc:
        print(f"speedplan: infeasible: {exc}", file=sys.stderr)
        return EXIT_CODES["infeasible"]
    except SolverError as exc:
        print(f"speedplan: solver failure: {exc}", file=sys.stderr)
        return EXIT_CODES["solver"]
    except (SpeedplanError, ValueError, OSError) as exc:
        print(f"speedplan: error: {exc}", file=sys.stderr)
        return EXIT_CODES["usage"]


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

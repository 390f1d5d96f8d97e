"""Command line: ``speedplan plan``, ``speedplan demo``, ``speedplan bench``.

Exit codes: 0 planned; 2 bad arguments or unreadable input; 3 infeasible request; 4 solver
failure; 5 limits exceeded (status ``"limits_exceeded"``, or with ``--strict`` any limit
beyond tolerance in ``verify()``).
"""

from __future__ import annotations

import argparse
import io
import logging
import math
import os
import re
import sys
import time
import warnings
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path as FsPath
from typing import IO, TYPE_CHECKING, Any

import numpy as np

from ._version import __version__
from .core.errors import (
    InfeasibleError,
    InvalidInputError,
    SolverError,
    SpeedplanError,
)
from .core.limits import Limits
from .core.log import logger
from .core.options import BACKENDS, GRIP_MODELS, REFINE_MODES, STANDSTILL_MODES, Standstill

if TYPE_CHECKING:
    from .geometry import Path, SpeedZone
    from .route import Route
    from .timing import SpeedProfile, Trajectory, Verification

__all__ = ["EXIT_CODES", "exit_status", "main"]

EXIT_CODES = {"ok": 0, "usage": 2, "infeasible": 3, "solver": 4, "limits": 5}
DEMO_PATH = "warehouse_loop.json"
DEMO_LIMITS = {"v_max": 2.0, "a_max": 1.0, "a_lat_max": 1.0, "j_max": 0.5}
TRAJECTORY_FORMATS = ("csv", "json")
STANDSTILL_HELP: dict[Standstill, str] = {
    "smooth": "acceleration 0 at a standstill, jerk-limited from the first instant",
    "free": "the paper's model: the acceleration may jump at a standstill",
}

#: Python argument names in error messages, as the flags a command-line user typed.
FLAGS = {name: "--" + name.replace("_", "-") for name in (
    "v_max", "a_max", "a_lat_max", "j_max", "a_decel", "j_lat_max", "yaw_rate_max", "v0", "a0",
    "vf", "af", "start_s", "standstill", "n", "ds", "backend", "refine", "dt", "format",
    "output_format", "precision", "dpi", "instances")}
_IDENTIFIER = re.compile(r"`([A-Za-z_][A-Za-z0-9_]*)`")


def flag_names(message: str) -> str:
    """``message`` with each quoted Python argument name replaced by its command-line flag.

    Examples
    --------
    >>> from speedplan.cli import flag_names
    >>> flag_names("`v_max` must be > 0; got -1.0")
    '`--v-max` must be > 0; got -1.0'
    >>> flag_names("unknown type '.md'; pass `format`, or see `Path`")
    "unknown type '.md'; pass `--format`, or see `Path`"
    """
    return _IDENTIFIER.sub(lambda m: f"`{FLAGS.get(m.group(1), m.group(1))}`", message)


EPILOG = """\
exit codes:
  0  planned (status optimal, refined, scaled or relaxed)
  2  bad arguments or unreadable input (the message names the argument or file)
  3  infeasible request (the message says which constraint and where)
  4  a solver failed and no feasible profile could be produced
  5  limits exceeded: status limits_exceeded (the trajectory exceeds a limit beyond
     tolerance even after local refinement), or with --strict any verify() failure;
     the output files are still written
"""


class _HelpFormatter(argparse.HelpFormatter):
    """Show ``(default: ...)`` for every option that has a default worth showing.

    Texts with line breaks (the exit-code table) are kept as written; others are wrapped.
    """

    def _fill_text(self, text: str, width: int, indent: str) -> str:
        if "\n" in text:
            return "".join(indent + line for line in text.splitlines(keepends=True))
        return super()._fill_text(text, width, indent)

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        hidden = action.default is None or action.default is False \
            or action.default == argparse.SUPPRESS
        if "%(default)" not in text and not hidden and action.option_strings:
            text += " (default: %(default)s)"
        return text


def _positive(kind: type[float] | type[int]) -> Any:
    def parse(text: str) -> float | int:
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a {kind.__name__}; got {text!r}") from None
        if not (math.isfinite(value) and value > 0):
            raise argparse.ArgumentTypeError(f"must be a finite number > 0; got {text!r}")
        return value

    parse.__name__ = f"positive {kind.__name__}"
    return parse


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
                       metavar="X", help=help_ + ("" if key in d else " (required)"))
    g.add_argument("--a-decel", type=float, default=None, metavar="X",
                   help="braking limit [m/s²] (default: a-max)")
    g.add_argument("--j-lat-max", type=float, default=None, metavar="X",
                   help="lateral jerk limit [m/s³] (default: none)")
    g.add_argument("--yaw-rate-max", type=float, default=None, metavar="X",
                   help="yaw-rate limit [rad/s] (default: none)")
    g.add_argument("--grip", choices=GRIP_MODELS, default="independent",
                   help="'ellipse': acceleration and lateral acceleration share one friction "
                        "ellipse (default: independent limits)")


def _add_common(p: argparse.ArgumentParser, out: str | None = None,
                plot: str | None = None) -> None:
    g = p.add_argument_group("boundary states")
    g.add_argument("--v0", type=float, default=0.0, metavar="V", help="start speed [m/s]")
    g.add_argument("--a0", type=float, default=0.0, metavar="A",
                   help="start acceleration [m/s²]")
    g.add_argument("--vf", type=float, default=0.0, metavar="V", help="end speed [m/s]")
    g.add_argument("--af", type=float, default=0.0, metavar="A", help="end acceleration [m/s²]")
    g.add_argument("--start-s", type=float, default=0.0, metavar="S",
                   help="VDA 5050 order only: where the vehicle is along the route [m] (an "
                   "order update while driving; --v0/--a0 its state there)")
    g.add_argument("--standstill", choices=STANDSTILL_MODES, default="smooth",
                   help="model at a standstill: "
                   + "; ".join(f"{k}: {v}" for k, v in STANDSTILL_HELP.items()))
    g = p.add_argument_group("solver")
    g.add_argument("--n", type=_positive(int), default=None, metavar="N",
                   help="uniform grid with N nodes (default: adaptive grid)")
    g.add_argument("--ds", type=_positive(float), default=None, metavar="DS",
                   help="uniform grid step [m] (default: adaptive grid)")
    g.add_argument("--backend", choices=BACKENDS, default="auto",
                   help="relaxation solver: banded interior point or Clarabel")
    g.add_argument("--refine", choices=REFINE_MODES, default="auto",
                   help="local refinement of an inexact relaxation (a banded interior-point "
                        "NLP, CasADi + IPOPT as fallback): auto = only when it is not exact")
    g.add_argument("--strict", action="store_true",
                   help="exit 5 if verify() finds any limit exceeded beyond its tolerance")
    g = p.add_argument_group("output")
    g.add_argument("--dt", type=_positive(float), default=0.01,
                   help="trajectory sampling period [s]")
    g.add_argument("-o", "--output", default=out, metavar="FILE",
                   help="trajectory file: .csv or .json, or - for standard output (the "
                   "summary then goes to standard error); '' writes none")
    g.add_argument("--precision", type=_positive(int), default=None, metavar="DIGITS",
                   help="significant digits of the CSV numbers (default: the shortest decimal "
                   "that reads back exactly)")
    g.add_argument("--output-format", choices=TRAJECTORY_FORMATS, default=None,
                   help="format of the trajectory on standard output (default: csv)")
    g.add_argument("--plot", default=plot, metavar="FIG",
                   help="figure file; its extension (.png, .svg, .pdf, ...) sets the format; "
                   "'' writes none")
    g.add_argument("--dpi", type=_positive(float), default=150,
                   help="resolution of raster figures [dots per inch]")


def _add_verbose(p: argparse.ArgumentParser, default: Any) -> None:
    p.add_argument("-v", "--verbose", action="store_true", default=default,
                   help="debug messages (files read and written, solver steps) on stderr")


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        prog="speedplan",
        description="Minimum-time speed planning along a path under speed, acceleration, "
        "lateral-acceleration and jerk limits.",
        epilog=EPILOG, formatter_class=_HelpFormatter,
    )
    ap.add_argument("--version", action="version", version=f"speedplan {__version__}")
    _add_verbose(ap, False)
    sub = ap.add_subparsers(dest="command", required=True, metavar="{plan,demo,bench,compile}")
    ap.set_defaults(_subparsers=sub.choices)
    p = sub.add_parser(
        "plan", help="plan a path file (CSV waypoints, JSON segments, VDA 5050 edge or order)",
        description="Plan the minimum-time speed law along a path file and report it; a VDA "
        "5050 order (nodes and edges) is planned as a route: stops at blocking actions, edge "
        "speed limits, node times.",
        epilog=EPILOG, formatter_class=_HelpFormatter)
    p.add_argument("pathfile",
                   help="path file: .csv waypoints, .json segments, a VDA 5050 NURBS edge or a "
                   "whole VDA 5050 order; - reads standard input")
    p.add_argument("--format", choices=("csv", "json"), default=None,
                   help="format of the path file (default: from the extension; on standard "
                   "input from the first character, { or [ meaning JSON)")
    _add_limits(p)
    _add_common(p)
    _add_verbose(p, argparse.SUPPRESS)
    limits = ", ".join(f"{k.replace('_', '-')} {v:g}" for k, v in DEMO_LIMITS.items())
    d = sub.add_parser(
        "demo", help="plan the bundled warehouse loop; write a trajectory and a figure",
        description=f"Plan the bundled warehouse loop ({DEMO_PATH}) with LGV limits "
        f"({limits}) and write the trajectory and the figure.",
        epilog=EPILOG, formatter_class=_HelpFormatter)
    _add_limits(d, DEMO_LIMITS)
    _add_common(d, out="speedplan-demo.csv", plot="speedplan-demo.png")
    _add_verbose(d, argparse.SUPPRESS)
    b = sub.add_parser(
        "bench", help="benchmark the solver on the paper's instance families",
        description="Solve random instances of the paper's 18 families and print, per "
        "family, how many relaxations were not exact and the median solve times.",
        formatter_class=_HelpFormatter)
    b.add_argument("--instances", type=_positive(int), default=3, help="instances per family")
    b.add_argument("--n", type=_positive(int), default=1000, help="grid size")
    _add_verbose(b, argparse.SUPPRESS)
    c = sub.add_parser(
        "compile", help="compile the solver's kernels into numba's cache",
        description="Compile every compiled kernel (relaxation, time law, refinement) into "
        "numba's on-disk cache, in parallel processes, and wait for them. `pip install .` "
        "already compiles them for the machine it builds on; run this where those do not "
        "apply (a wheel built on another kind of machine, another numba, NUMBA_CACHE_DIR): "
        "the first plan then runs the compiled kernels instead of their fallbacks. The cache "
        "is next to the package, or under NUMBA_CACHE_DIR.",
        formatter_class=_HelpFormatter)
    c.add_argument("--serial", action="store_true",
                   help="compile in this process, one family after the other")
    _add_verbose(c, argparse.SUPPRESS)
    return ap


def _run_compile(args: argparse.Namespace) -> int:
    from .core.jit import compile_families

    try:
        seconds = compile_families(parallel=not args.serial)
    except RuntimeError as exc:
        print(f"speedplan: {exc}", file=sys.stderr)
        return EXIT_CODES["solver"]
    for name, sec in seconds.items():
        print(f"{name}: ready after {sec:.1f} s")
    return EXIT_CODES["ok"]


# ---- checks done before planning ------------------------------------------------------------
def _writable(option: str, file: str) -> None:
    folder = FsPath(file).parent
    if not folder.is_dir():
        raise InvalidInputError(
            f"`{option}` {file!r}: directory {str(folder)!r} does not exist; create it first"
        )
    if not os.access(folder, os.W_OK):
        raise InvalidInputError(f"`{option}` {file!r}: directory {str(folder)!r} is not "
                                "writable")
    if FsPath(file).is_dir():
        raise InvalidInputError(f"`{option}` {file!r} is a directory; give a file name")


def _output_format(args: argparse.Namespace) -> str | None:
    """The trajectory format, after checking ``--output`` (None: no trajectory)."""
    out, fmt = args.output, args.output_format
    if not out:
        if fmt is not None:
            raise InvalidInputError("`--output-format` needs `-o -` (standard output)")
        return None
    if out == "-":
        return fmt or "csv"
    suffix = FsPath(out).suffix.lower().lstrip(".")
    if suffix not in TRAJECTORY_FORMATS:
        raise InvalidInputError(
            f"`--output` {out!r}: unknown trajectory file type "
            f"{FsPath(out).suffix or '(no extension)'}; use .csv or .json, or - for standard "
            "output"
        )
    if fmt is not None and fmt != suffix:
        raise InvalidInputError(
            f"`--output-format` {fmt} contradicts the extension of `--output` {out!r}"
        )
    _writable("--output", out)
    return suffix


def _check_plot(file: str | None) -> None:
    if not file:
        return
    try:
        from matplotlib.backend_bases import FigureCanvasBase
    except ImportError as exc:
        raise InvalidInputError(
            "`--plot` needs matplotlib: pip install 'speedplan[plot]'"
        ) from exc
    types = FigureCanvasBase.get_supported_filetypes()
    suffix = FsPath(file).suffix.lower().lstrip(".")
    if suffix not in types:
        raise InvalidInputError(
            f"`--plot` {file!r}: unknown figure type {FsPath(file).suffix or '(no extension)'}"
            f"; use one of {', '.join('.' + t for t in sorted(types))}"
        )
    _writable("--plot", file)


# ---- planning -------------------------------------------------------------------------------
def _metadata(profile: SpeedProfile, args: argparse.Namespace, path_name: str | None
              ) -> dict[str, Any]:
    """What the trajectory file records about how it was made (for a reader, later)."""
    return {"path_file": path_name, **profile.metadata, "dt": args.dt}


def _stdin_text(args: argparse.Namespace) -> str:
    """Standard input, read once (an order check and the path reader both look at it)."""
    if getattr(args, "_stdin", None) is None:
        args._stdin = sys.stdin.read()
    text: str = args._stdin
    return text


def _read_order(args: argparse.Namespace, pathfile: str | FsPath) -> Route | None:
    """The [`Route`][speedplan.Route] when the input is a VDA 5050 order, else ``None``."""
    import json

    from .io import read_route

    if str(pathfile) == "-":
        text, name = _stdin_text(args), "<stdin>"
    else:
        fs = FsPath(pathfile)
        if fs.suffix.lower() != ".json" or not fs.is_file():
            return None
        try:
            text = fs.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            return None  # the path reader reports it
        name = fs.name
    try:
        doc = json.loads(text)
    except json.JSONDecodeError:
        return None
    if not (isinstance(doc, dict) and "nodes" in doc and "edges" in doc):
        return None
    buf = io.StringIO(text)
    buf.name = name
    return read_route(buf)


def _read_input(args: argparse.Namespace, pathfile: str | FsPath
                ) -> tuple[Path, list[SpeedZone], str]:
    from .io import read_path, read_zones

    if str(pathfile) == "-":
        text = _stdin_text(args)

        def stream() -> io.StringIO:
            buf = io.StringIO(text)
            buf.name = "<stdin>"  # named in error messages
            return buf

        path = read_path(stream(), format=args.format)
        return path, read_zones(stream(), format=args.format), "<stdin>"
    fmt = getattr(args, "format", None)
    return read_path(pathfile, format=fmt), read_zones(pathfile, format=fmt), \
        FsPath(pathfile).name


def _limits(args: argparse.Namespace) -> Limits:
    return Limits(v_max=args.v_max, a_max=args.a_max, a_lat_max=args.a_lat_max,
                  j_max=args.j_max, a_decel=args.a_decel, j_lat_max=args.j_lat_max,
                  yaw_rate_max=args.yaw_rate_max, grip=args.grip)


def _write_outputs(args: argparse.Namespace, traj: Trajectory, info: IO[str]) -> None:
    out_format = _output_format(args)
    if out_format is None:
        return
    target: Any = sys.stdout if args.output == "-" else FsPath(args.output)
    if out_format == "json":
        traj.to_json(target)
        if args.output == "-":
            sys.stdout.write("\n")
    else:
        traj.to_csv(target, precision=args.precision)
    where = "standard output" if args.output == "-" else args.output
    print(f"wrote     {where} ({len(traj)} samples every {args.dt} s)", file=info)


def _conclude(args: argparse.Namespace, status: str, check: Verification,
              caught: list[warnings.WarningMessage]) -> int:
    """Print the warnings caught while planning, then the exit code's reason; return the code."""
    for w in caught:
        print(f"warning: {w.message}", file=sys.stderr)
    code, reason = exit_status(status, check.violations, strict=args.strict)
    if reason:
        print(f"speedplan: {reason}", file=sys.stderr)
    return code


def _run_route(args: argparse.Namespace, route: Route, name: str, info: IO[str]) -> int:
    """``speedplan plan order.json``: plan the order's released base, print the node times."""
    from .route_plan import plan_route

    if args.vf != 0.0 or args.af != 0.0:
        raise InvalidInputError(
            "--vf/--af: an order ends at rest on its last released node; drop them"
        )
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        profile = plan_route(route, _limits(args), start_s=args.start_s, v0=args.v0,
                             a0=args.a0, n=args.n, ds=args.ds, standstill=args.standstill,
                             backend=args.backend, refine=args.refine)
    elapsed = time.perf_counter() - t0
    check = profile.verification
    order = f" (order {route.order_id})" if route.order_id else ""
    print(f"route     {name}{order}: {route.length:.3f} m, {len(route.base_edges)} edges, "
          f"{len(profile.legs)} stop-to-stop legs", file=info)
    print(f"duration  {profile.duration:.4f} s   (planned in {elapsed:.3f} s)", file=info)
    print(f"status    {profile.status}   gap={profile.gap:.2e}", file=info)
    print("node      s [m]      t [s]   stop", file=info)
    stops = set(np.round(route.stop_s, 9).tolist())
    for node, s, t_node in zip(route.base_nodes, route.node_s, profile.node_times,
                               strict=True):
        when = "passed" if np.isnan(t_node) else f"{t_node:9.3f}"
        print(f"  {node.node_id:8s}{s:9.3f}  {when:>9s}   "
              f"{'yes' if round(float(s), 9) in stops else ''}", file=info)
    print("realised maxima / limits:", file=info)
    print("  " + check.summary().replace("\n", "\n  "), file=info)
    traj = profile.sample(args.dt)
    traj = replace(traj, metadata={"path_file": name, **traj.metadata})
    _write_outputs(args, traj, info)
    if args.plot:
        from .plot import plot_route

        plot_route(profile, args.plot, trajectory=traj, dpi=args.dpi)
        print(f"wrote     {args.plot}", file=info)
    return _conclude(args, profile.status, check, caught)


def _run_plan(args: argparse.Namespace, pathfile: str | FsPath) -> int:
    from .plan import plan

    _output_format(args)
    _check_plot(args.plot)
    info: IO[str] = sys.stderr if args.output == "-" else sys.stdout
    limits = _limits(args)
    route = _read_order(args, pathfile)
    if route is not None:
        name = "<stdin>" if str(pathfile) == "-" else FsPath(pathfile).name
        return _run_route(args, route, name, info)
    if args.start_s != 0.0:
        raise InvalidInputError("--start-s applies to VDA 5050 orders only")
    with warnings.catch_warnings(record=True) as caught:  # printed as one line each, below
        warnings.simplefilter("always")
        path, zones, name = _read_input(args, pathfile)
        t0 = time.perf_counter()
        profile = plan(path, limits, n=args.n, ds=args.ds, v0=args.v0, a0=args.a0, vf=args.vf,
                       af=args.af, zones=zones or None, standstill=args.standstill,
                       backend=args.backend, refine=args.refine)
    elapsed = time.perf_counter() - t0
    check = profile.verification or profile.verify()
    print(f"path      {name}: {path.length:.3f} m, {profile.s.size} grid nodes", file=info)
    print(f"duration  {profile.duration:.4f} s   (planned in {elapsed:.3f} s)", file=info)
    print(f"status    {profile.status}   exact={profile.exact}   gap={profile.gap:.2e}",
          file=info)
    print("realised maxima / limits:", file=info)
    print("  " + check.summary().replace("\n", "\n  "), file=info)
    if _output_format(args) is not None:
        traj = replace(profile.sample(args.dt), metadata=_metadata(profile, args, name))
        _write_outputs(args, traj, info)
    if args.plot:
        from .plot import plot_profile

        plot_profile(profile, args.plot, dt=args.dt, dpi=args.dpi)
        print(f"wrote     {args.plot}", file=info)
    return _conclude(args, profile.status, check, caught)


def _has_matplotlib() -> bool:
    try:
        import matplotlib.backend_bases  # noqa: F401
    except ImportError:
        return False
    return True


def _run_demo(args: argparse.Namespace) -> int:
    """``speedplan demo``: the figure is skipped, with a hint, when matplotlib is missing."""
    if args.plot and not _has_matplotlib():
        print(f"note: no figure ({args.plot}): matplotlib is not installed; "
              "pip install 'speedplan[plot]' to get it", file=sys.stderr)
        args.plot = None
    return _run_plan(args, _bundled_paths_dir() / DEMO_PATH)


def exit_status(status: str, violations: dict[str, float], *, strict: bool = False
                ) -> tuple[int, str | None]:
    """Exit code of ``speedplan plan`` for a profile's status and ``verify()`` violations.

    Returns the code and, when it is not 0, why.

    Examples
    --------
    >>> from speedplan.cli import exit_status
    >>> exit_status("optimal", {})
    (0, None)
    >>> exit_status("limits_exceeded", {"jerk": 1.31})[0]
    5
    >>> exit_status("optimal", {"jerk": 1.31})
    (0, None)
    >>> exit_status("optimal", {"jerk": 1.31}, strict=True)
    (5, 'limits exceeded (--strict): jerk 1.310× the limit')
    """
    worst = ", ".join(f"{k} {r:.3f}× the limit" for k, r in violations.items())
    if status == "limits_exceeded":
        return EXIT_CODES["limits"], (
            "limits exceeded: the trajectory exceeds a limit beyond its tolerance even after "
            f"local refinement (status limits_exceeded{'; ' + worst if worst else ''})"
        )
    if strict and violations:
        return EXIT_CODES["limits"], f"limits exceeded (--strict): {worst}"
    return EXIT_CODES["ok"], None


def _run_bench(args: argparse.Namespace) -> int:
    from .solve import solve_discrete
    from .solve.paper import FAMILIES, paper_instance

    print(f"paper's families, {args.instances} random instance(s) each, n = {args.n}; wall-clock "
          "medians:\n  relaxation [s]: setup + solve of the convex relaxation\n"
          "  solve_discrete [s]: the whole call (relaxation, plus the refinement when not exact)")
    print(f"{'W':8s} {'A':5s} {'J':6s} {'non-exact':>9s} {'relaxation [s]':>15s} "
          f"{'solve_discrete [s]':>19s}")
    for i, fam in enumerate(FAMILIES):
        relax, total, non_exact = [], [], 0
        for k in range(args.instances):
            inst = paper_instance(*fam, n=args.n, seed=1000 * i + k)
            sol = solve_discrete(inst.w_max, inst.A, inst.J)
            relax.append(sol.relaxation.time if sol.relaxation else 0.0)
            total.append(sol.solve_time)
            non_exact += not sol.exact
        print(f"{fam[0]:8s} {fam[1]:5s} {fam[2]:6s} {non_exact:>5d}/{args.instances:<3d} "
              f"{float(np.median(relax)):15.4f} {float(np.median(total)):19.4f}   "
              f"[{i + 1}/{len(FAMILIES)}]", flush=True)
    return EXIT_CODES["ok"]


class _StderrHandler(logging.StreamHandler):  # type: ignore[type-arg]
    """Writes to the current ``sys.stderr`` (tests and callers may swap it)."""

    def __init__(self) -> None:
        super().__init__()
        self.setFormatter(logging.Formatter("speedplan %(levelname)s: %(message)s"))

    def emit(self, record: logging.LogRecord) -> None:
        self.stream = sys.stderr
        super().emit(record)


def _configure_logging(verbose: bool) -> None:
    handlers = [h for h in logger.handlers if isinstance(h, _StderrHandler)]
    if verbose and not handlers:
        logger.addHandler(_StderrHandler())
        logger.setLevel(logging.DEBUG)
    elif not verbose:
        for h in handlers:
            logger.removeHandler(h)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``speedplan`` command; returns the exit code."""
    parser = _parser()
    args, unknown = parser.parse_known_args(argv)
    if unknown:  # reported with the subcommand's own usage, not the top level's
        parser_of = args._subparsers.get(args.command, parser)
        parser_of.error(f"unrecognized arguments: {' '.join(unknown)}")
    _configure_logging(args.verbose)
    try:
        if args.command == "plan":
            return _run_plan(args, args.pathfile)
        if args.command == "demo":
            return _run_demo(args)
        if args.command == "compile":
            return _run_compile(args)
        return _run_bench(args)
    except BrokenPipeError:  # the reader of our output left (e.g. `| head`): stop quietly
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_CODES["ok"]
    except InfeasibleError as exc:
        print(f"speedplan: infeasible: {flag_names(str(exc))}", file=sys.stderr)
        return EXIT_CODES["infeasible"]
    except SolverError as exc:
        print(f"speedplan: solver failure: {flag_names(str(exc))}", file=sys.stderr)
        return EXIT_CODES["solver"]
    except (SpeedplanError, ValueError, OSError) as exc:
        print(f"speedplan: error: {flag_names(str(exc))}", file=sys.stderr)
        return EXIT_CODES["usage"]


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

"""Build the corpus of ``plan()`` problems whose relaxation is not exact (for bench_refine.py).

``plan()`` needs the IPOPT refinement mostly when a boundary state is moving: a vehicle that
starts braking (``a0 < 0``) has a lower envelope ``w_min`` and the relaxation is no longer
exact (the paper's Section 5.1). This script draws such requests (seeded), models each with
:func:`speedplan.model.build_model` on the default (adaptive) grid, keeps those whose
relaxation violates a jerk row, and saves the :class:`~speedplan.solve.DiscreteProblem` arrays,
the relaxed ``w`` (scaled as ``solve_problem`` scales it) and the certified lower bound to an
``.npz`` file, so that ``bench_refine.py`` measures the refinement alone, independent of the
model layer and of later changes to the relaxation.

The issue's case (``L = 8.149...``, ``v0 = 0.0934...``, ``a0 = -0.1535...``) is always the
first entry, on the default grid and on ``n = 2000``.

With ``--lateral`` the requests are instead those of ``benchmarks/lateral_exactness.py``'s
fuzz (same seed, same draws: random G2 waypoint paths with lateral-jerk and yaw-rate limits,
from rest to rest), every leg whose relaxation is not exact: with these rows the relaxation is
almost never exact and every ``plan()`` goes through the refinement.

Usage::

    python benchmarks/refine_corpus.py --out benchmarks/data/refine_corpus.npz --draws 400
    python benchmarks/refine_corpus.py --lateral --draws 40 --max-keep 200 --out /tmp/lat.npz
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path as FsPath
from typing import Any

import numpy as np

import speedplan as sp
from speedplan.core.errors import InfeasibleError, InvalidInputError, SolverError
from speedplan.geometry import Line
from speedplan.io import read_path
from speedplan.model import PlanRequest, build_model
from speedplan.solve import DiscreteProblem, solve_problem

PATHS = FsPath(__file__).resolve().parents[1] / "paths"
ISSUE_LIMITS = sp.Limits(v_max=1.5103489923280469, a_max=0.8675731399347792, a_lat_max=1,
                         j_max=0.1324661827707745)
ISSUE_KW: dict[str, Any] = {"v0": 0.09343837197243295, "a0": -0.15353125453853034}
ISSUE_PATH = sp.Path.from_segments([Line(8.149176458679765)])
FIELDS = ("s", "w_max", "accel", "decel", "jerk", "w_min")


def problem_arrays(p: DiscreteProblem) -> dict[str, Any]:
    """The arrays of ``p`` by field name (``w_min`` zeros when absent)."""
    out: dict[str, Any] = {f: getattr(p, f) for f in FIELDS}
    if p.w_min is None:
        out["w_min"] = np.zeros(p.n)
    out["ends"] = np.array([p.w_start, p.w_end])
    for j, lat in enumerate(p.lateral_families):  # lateral jerk, yaw rate
        out[f"lat{j}_coef"], out[f"lat{j}_bound"] = lat.coef, lat.bound
    return out


def draw_request(rng: np.random.Generator, paths: list[tuple[str, sp.Path]]) -> dict[str, Any]:
    """A random request with a moving start that brakes (and sometimes a moving end)."""
    name, path = paths[int(rng.integers(len(paths)))]
    if name == "line":
        path = sp.Path.from_segments([Line(float(rng.uniform(1.0, 40.0)))])
    lim = sp.Limits(v_max=float(rng.uniform(0.3, 3.0)), a_max=float(rng.uniform(0.2, 2.0)),
                    a_lat_max=float(rng.uniform(0.5, 2.0)), j_max=float(10 ** rng.uniform(-1, 0.5)))
    # Start moving and braking: v0 + a0|a0|/(2 j) (the least speed it passes) in [0, 0.9 v0].
    v0 = float(rng.uniform(0.0, 0.5 * lim.v_max))
    v_least = v0 * float(rng.uniform(0.0, 0.9))
    a0 = -min(lim.a_max, float(np.sqrt(2.0 * lim.j_max * (v0 - v_least))))
    kw: dict[str, Any] = {"v0": v0, "a0": a0}
    if rng.uniform() < 0.3:
        kw["vf"] = float(rng.uniform(0.0, lim.v_max))
        kw["af"] = float(rng.uniform(-1.0, 1.0) * lim.a_max)
    return {"name": name, "path": path, "limits": lim, "kw": kw}


LGV = dict(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)


def lateral_jobs(draws: int, seed: int) -> list[tuple[str, sp.Path, sp.Limits, dict[str, Any],
                                                      int | None]]:
    """The requests of ``lateral_exactness.py``'s fuzz (``--cases draws --seed seed``)."""
    rng = np.random.default_rng(seed)
    jobs: list[tuple[str, sp.Path, sp.Limits, dict[str, Any], int | None]] = []
    for i in range(draws):
        k = int(rng.integers(4, 9))
        pts = np.cumsum(rng.uniform(-10, 10, size=(k, 2)), axis=0)
        try:
            path = sp.Path.from_waypoints(pts, max_deviation=float(rng.uniform(0.1, 1.0)))
        except InvalidInputError:
            continue
        j_lat = float(np.exp(rng.uniform(np.log(0.05), np.log(3))))
        yaw = None if rng.random() < 0.3 else float(rng.uniform(0.2, 2))
        jobs.append((f"fuzz{i} j_lat={j_lat:.3g} yaw={yaw if yaw is None else f'{yaw:.3g}'}",
                     path, sp.Limits(**LGV, j_lat_max=j_lat, yaw_rate_max=yaw), {}, None))
    return jobs


def relax(p: DiscreteProblem) -> tuple[Any, float]:
    """Relaxation only (``refine='never'``) and the scale ``max(w_max)`` refine_ipopt sees."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return solve_problem(p, refine="never", backend="auto"), float(np.max(p.w_max))


def main(argv: list[str] | None = None) -> None:
    """Draw requests, keep the non-exact ones, save them."""
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--out", default=str(FsPath(__file__).parent / "data" / "refine_corpus.npz"))
    ap.add_argument("--draws", type=int, default=400)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--max-keep", type=int, default=24)
    ap.add_argument("--lateral", action="store_true",
                    help="lateral_exactness.py's fuzz requests (--draws cases) instead")
    args = ap.parse_args(argv)
    paths = [("line", ISSUE_PATH)] + [
        (f, read_path(PATHS / f)) for f in ("warehouse_loop.json", "u_turn.json",
                                            "nurbs_edge.json", "aisle_corners.csv")
    ]
    rng = np.random.default_rng(args.seed)
    jobs: list[tuple[str, sp.Path, sp.Limits, dict[str, Any], int | None]] = [
        ("issue", ISSUE_PATH, ISSUE_LIMITS, ISSUE_KW, None),
        ("issue n=2000", ISSUE_PATH, ISSUE_LIMITS, ISSUE_KW, 2000),
    ]
    if args.lateral:
        jobs = lateral_jobs(args.draws, args.seed)
    else:
        for _ in range(args.draws):
            d = draw_request(rng, paths)
            jobs.append((d["name"], d["path"], d["limits"], d["kw"], None))
    saved: dict[str, Any] = {}
    labels: list[str] = []
    t0 = time.perf_counter()
    for k, (name, path, lim, kw, n) in enumerate(jobs):
        if len(labels) >= args.max_keep:
            break
        try:  # every leg with a free speed law (not a forced max-jerk motion)
            problems = [leg.problem for leg in
                        build_model(PlanRequest.create(path, lim, n=n, **kw)).legs
                        if hasattr(leg, "problem")]
        except (InfeasibleError, InvalidInputError, SolverError):
            continue
        for leg, p in enumerate(problems):
            if len(labels) >= args.max_keep:
                break
            try:
                sol, w_scale = relax(p)
            except (InfeasibleError, InvalidInputError, SolverError):
                continue
            if sol.exact:
                continue
            label = (f"{name}{f' leg {leg}' if len(problems) > 1 else ''} n={p.n} "
                     f"v_max={lim.v_max:.3g} a_max={lim.a_max:.3g} j_max={lim.j_max:.3g} "
                     + " ".join(f"{a}={v:.3g}" for a, v in kw.items()))
            i = len(labels)
            labels.append(label)
            for key, val in problem_arrays(p).items():
                saved[f"{i}/{key}"] = val
            saved[f"{i}/w0"] = sol.relaxation.w / w_scale
            saved[f"{i}/lower_bound"] = np.array(sol.lower_bound)
            print(f"{i:3d} (draw {k}) {label}: violation {sol.relaxation.jerk_violation:.3g}",
                  flush=True)
    saved["labels"] = np.array(labels)
    np.savez_compressed(args.out, **saved)
    print(f"# saved {len(labels)} problems to {args.out} in {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()

"""Whether the many jerk reversals of some comfort-limited corners are the optimum's or the grid's.

Usage::

    python benchmarks/reversal_convergence.py [--plans 200] [--seed 1] [--factors 2] [--verbose]

Plans the random G2 comfort plans of `bench_comfort.py` (``--plans`` draws of ``--seed``) with
and without their comfort limits and takes the corners whose jerk sign reversals (``|j| >=
0.25 j_max`` in the 100 Hz jerk column, `oracles.corner_reversals`) exceed ``2 × without + 4``.
Their plans are planned again on the default grid with every cell cut into ``k`` for each
``k`` of ``--factors`` (``2,4`` is slower), the strategy's coarser grids off (a stalled solve
is answered by the other backend on the same grid: `oracles.subdivided_default_grids`). Per
corner: its 100 Hz count on each grid, and the reversals between its *converged* jerk phases
(runs of nodes with ``|j| >= 0.25 j_max`` of one sign that last as many seconds on every
grid, not a notch of a few cells that shrinks with the grid); every solved grid is searched
for a zigzag at the grid's frequency (>= 6 nodes whose jerk steps alternate in sign, each
>= 0.01 j_max). Printed: the corners over the threshold, how many keep their 100 Hz count on
every grid, exceed it with converged reversals alone, or zigzag, and every plan whose finer
grid failed or lacked ``k`` times the cells; ``--verbose`` adds a row per corner.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

import speedplan as sp

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from bench_comfort import draw_g2_case
from oracles import corner_reversals, subdivided_default_grids

THRESHOLD = 0.25  # |j| / j_max that counts, as in `oracles.corner_reversals`
SLACK = 0.03  # [s] a phase on a finer grid may start or end this much off and still match
ZIGZAG_NODES, ZIGZAG_STEP = 6, 0.01


def quiet_plan(path: sp.Path, lim: sp.Limits, k: int = 1) -> tuple[sp.SpeedProfile, int]:
    """``plan(path, lim)`` without warnings, on the default grid cut ``k`` times if ``k > 1``.

    Returns
    -------
    profile, nodes : SpeedProfile, int
        The plan, and the nodes of the default grids it built (legs share their ends).
    """
    from speedplan.model import leg_grid

    sizes: list[int] = []
    with warnings.catch_warnings(), contextlib.ExitStack() as stack:
        warnings.simplefilter("ignore")
        if k > 1:
            stack.enter_context(subdivided_default_grids(k))
        built = leg_grid.default_grid
        stack.callback(setattr, leg_grid, "default_grid", built)

        def record(*args: Any, **kw: Any) -> np.ndarray:
            sizes.append((s := built(*args, **kw)).size)
            return s

        leg_grid.default_grid = record
        prof = sp.plan(path, lim)
    return prof, sum(sizes) - max(len(sizes) - 1, 0)


def node_jerk(prof: sp.SpeedProfile) -> np.ndarray:
    """The discrete jerk ``D2_k sqrt(w_k) / 2`` at every node of ``prof.s`` (0 at leg ends).

    This is the law's jerk at full resolution: the 100 Hz jerk column samples it.
    """
    parts = []
    for leg in prof.legs:
        s, w = leg.s, np.maximum(leg.solution.w, 0.0)
        h0, h1 = np.diff(s)[:-1], np.diff(s)[1:]
        d2 = 2.0 * (w[:-2] / (h0 * (h0 + h1)) - w[1:-1] / (h0 * h1) + w[2:] / (h1 * (h0 + h1)))
        parts.append(np.concatenate(([0.0], 0.5 * d2 * np.sqrt(w[1:-1]))))
    return np.concatenate([*parts, [0.0]])


def corner_windows(traj: sp.Trajectory) -> list[tuple[float, float]]:
    """``(first, last)`` time of each corner of `oracles.corner_reversals` in ``traj``."""
    curved = np.abs(np.asarray(traj.curvature)) > 1e-12
    edges = np.flatnonzero(np.diff(np.concatenate(([0], curved.astype(int), [0]))))
    t = np.asarray(traj.t)
    return [(float(t[a]), float(t[b - 1])) for a, b in zip(edges[::2], edges[1::2], strict=True)]


def phases(t: np.ndarray, j: np.ndarray, j_max: float) -> list[dict[str, float]]:
    """The jerk phases among nodes at times ``t`` with jerk ``j``.

    Returns
    -------
    list of dict
        Per run of nodes with ``|j| >= THRESHOLD j_max`` of one sign: ``sign``, start
        ``t0`` [s], ``cells`` it spans and ``dur``, the seconds to the node after it.
    """
    keep = np.flatnonzero(np.abs(j) >= THRESHOLD * j_max)
    if keep.size == 0:
        return []
    sign = np.sign(j[keep])
    out = []
    for run in np.split(keep, np.flatnonzero(np.diff(sign)) + 1):
        a, b = run[0], run[-1]
        out.append(dict(sign=float(np.sign(j[a])), t0=float(t[a]), cells=float(b - a + 1),
                        dur=float(t[min(b + 1, t.size - 1)] - t[a])))
    return out


def match(x: dict[str, float], others: list[dict[str, float]]) -> dict[str, float] | None:
    """The run of ``others`` of ``x``'s sign that overlaps it most (``SLACK`` allowed)."""
    def over(y: dict[str, float]) -> float:
        return min(x["t0"] + x["dur"], y["t0"] + y["dur"]) - max(x["t0"], y["t0"])

    same = [y for y in others if y["sign"] == x["sign"] and over(y) > -SLACK]
    return max(same, key=over, default=None)


def classify(runs: list[list[dict[str, float]]], factors: list[int]) -> list[str]:
    """``"cont"``, ``"notch"`` or ``"unclear"`` for each phase of the default grid.

    ``runs``: a corner's `phases` on the default grid, then on each grid of ``factors``
    (ascending). ``cont``: matched on every finer grid and lasting the same within 35 % (or
    over 4 cells and 50 ms); ``notch``: missing on a finer grid, or shrinking with it (on the
    finest, fewer than ``sqrt(k)`` times the cells and under 60 % of the time).
    """
    kinds = []
    for x in runs[0]:
        ys = [match(x, r) for r in runs[1:]]
        if any(y is None for y in ys):
            kinds.append("notch")
            continue
        durs = [x["dur"]] + [y["dur"] for y in ys]
        last = ys[-1]
        if min(durs) >= 0.65 * max(durs) or (x["cells"] > 4 and x["dur"] >= 0.05):
            kinds.append("cont")
        elif last["cells"] < np.sqrt(factors[-1]) * x["cells"] and last["dur"] < 0.6 * x["dur"]:
            kinds.append("notch")
        else:
            kinds.append("unclear")
    return kinds


def zigzags(j: np.ndarray, j_max: float) -> list[tuple[int, int]]:
    """``(first, last)`` node of each zigzag of the jerk ``j`` at the grid's frequency.

    A zigzag: >= ``ZIGZAG_NODES`` nodes whose steps alternate in sign, each >= ``ZIGZAG_STEP
    j_max``.
    """
    d = np.diff(j)
    big = np.abs(d) >= ZIGZAG_STEP * j_max
    alt = (np.sign(d[1:]) != np.sign(d[:-1])) & big[1:] & big[:-1]
    edges = np.flatnonzero(np.diff(np.concatenate(([0], alt.astype(int), [0]))))
    return [(int(a), int(b) + 1) for a, b in zip(edges[::2], edges[1::2], strict=True)
            if b - a + 2 >= ZIGZAG_NODES]


def compare(index: int, path: sp.Path, lim: sp.Limits, prof: sp.SpeedProfile, grid: int,
            over: dict[int, int], factors: list[int], out: dict[str, list]) -> None:
    """Plan ``path`` on the finer grids and record each over-threshold corner of ``over``.

    Parameters
    ----------
    index, path, lim, prof, grid
        The draw's index, its path, comfort limits, plan and nodes of its default grid.
    over : dict
        ``corner: 2 × reversals without comfort limits + 4`` of the corners over it.
    factors : list of int
        The cuts per cell of the finer grids, ascending.
    out : dict
        Appended to: ``rows`` (a dict per corner), ``grids`` (whether each solved grid
        zigzags), ``skipped`` (why, index, over): a plan is compared only if every grid has
        ``k`` times the default grid's cells and answered with at least their nodes.
    """
    profs = [prof]
    for k in [1, *factors]:
        try:
            fine, built = (prof, grid) if k == 1 else quiet_plan(path, lim, k)
        except sp.SpeedplanError as exc:
            out["skipped"].append((f"x{k}: {type(exc).__name__}: {exc}"[:200], index, over))
            return
        if abs((built - 1) / (k * (grid - 1)) - 1) > 0.1 or fine.s.size < 0.9 * built:
            answered = sorted({a.name for a in fine.attempts if a.outcome == "answered"})
            out["skipped"].append((f"x{k}: {fine.s.size} nodes on a grid of {built}, default "
                                   f"{grid} ({', '.join(answered)})", index, over))
            return
        profs += [fine] if k > 1 else []
    jerks, counts, windows, zz = [], [], [], []
    for p in profs:
        jerks.append(node_jerk(p))
        assert jerks[-1].size == p.s.size == p.t.size
        traj = p.sample(0.01)
        counts.append(corner_reversals(traj, lim.j_max))
        windows.append(corner_windows(traj))
        zz.append(zigzags(jerks[-1], lim.j_max))
        out["grids"].append(bool(zz[-1]))
    if any(len(c) != len(counts[0]) for c in counts):
        out["skipped"].append((f"corners per grid {[len(c) for c in counts]}", index, over))
        return
    for c, limit in over.items():
        runs, hit = [], False
        for p, j, win, ranges in zip(profs, jerks, windows, zz, strict=True):
            sel = np.flatnonzero((p.t >= win[c][0]) & (p.t <= win[c][1]))
            runs.append(phases(p.t[sel], j[sel], lim.j_max))
            hit |= sel.size > 0 and any(a <= sel[-1] and b >= sel[0] for a, b in ranges)
        kinds = classify(runs, factors)
        signs = [x["sign"] for x, kind in zip(runs[0], kinds, strict=True) if kind == "cont"]
        out["rows"].append(dict(
            plan=index, corner=c, limit=limit, status=prof.status,
            counts=[n[c] for n in counts], nodes=[max(len(r) - 1, 0) for r in runs],
            converged=int(np.count_nonzero(np.diff(signs))), notches=kinds.count("notch"),
            unclear=kinds.count("unclear"), zigzag=hit))


def main() -> int:
    """Draw, plan, compare and print (see the module docstring)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plans", type=int, default=200)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--factors", default="2", help="comma-separated cuts per cell, e.g. 2,4")
    ap.add_argument("--verbose", action="store_true", help="print a row per corner")
    args = ap.parse_args()
    factors = sorted(int(f) for f in args.factors.split(","))
    print(f"speedplan from {Path(sp.__file__).parent}")
    start = time.perf_counter()
    rng = np.random.default_rng(args.seed)
    out: dict[str, list] = dict(rows=[], skipped=[], grids=[], errors=[])
    drawn = corners = n_over = over_plans = 0
    while drawn < args.plans:
        case = draw_g2_case(rng, (5.0, 500.0))
        if case is None:
            continue
        drawn += 1
        path, plain, comfort = case
        lim = sp.Limits(**plain, **comfort)
        try:
            (prof, grid), (base, _) = quiet_plan(path, lim), quiet_plan(path, sp.Limits(**plain))
        except sp.SpeedplanError as exc:
            out["errors"].append(f"plan {drawn - 1}: {type(exc).__name__}: {exc}"[:200])
            continue
        got = corner_reversals(prof.sample(0.01), lim.j_max)
        ref = corner_reversals(base.sample(0.01), lim.j_max)
        if len(got) != len(ref):
            continue
        corners += len(got)
        over = {c: 2 * r + 4 for c, (g, r) in enumerate(zip(got, ref, strict=True))
                if g > 2 * r + 4}
        if over:
            over_plans += 1
            n_over += len(over)
            compare(drawn - 1, path, lim, prof, grid, over, factors, out)
    rows, grids, n = out["rows"], "/".join(f"x{k}" for k in [1, *factors]), len(out["rows"])
    for r in rows if args.verbose else []:
        print(f"plan {r['plan']:3d} corner {r['corner']} {r['status']}: 2x+4 = {r['limit']}; "
              f"100 Hz {grids} {'/'.join(map(str, r['counts']))}, nodes "
              f"{'/'.join(map(str, r['nodes']))}; converged {r['converged']}, notches "
              f"{r['notches']}, unclear {r['unclear']}{', ZIGZAG' if r['zigzag'] else ''}")
    print(f"random G2 comfort plans (seed {args.seed}): {drawn} drawn, {len(out['errors'])} "
          f"errors, {corners} corners", *(f"\n  {e}" for e in out["errors"]), sep="")
    print(f"corners over 2x+4: {n_over} in {over_plans} plans; compared on {grids}: {n}\n"
          f"  100 Hz count the same on every grid: "
          f"{sum(len(set(r['counts'])) == 1 for r in rows)} of {n}\n"
          f"  over 2x+4 with converged reversals alone: "
          f"{sum(r['converged'] > r['limit'] for r in rows)} of {n} (with a notch: "
          f"{sum(r['notches'] > 0 for r in rows)}, with an unclear phase: "
          f"{sum(r['unclear'] > 0 for r in rows)})\n"
          f"  grid-frequency jerk zigzag (>= {ZIGZAG_NODES} nodes, steps >= {ZIGZAG_STEP} j_max)"
          f" in the corner: {sum(r['zigzag'] for r in rows)} of {n}; anywhere on the "
          f"path: {sum(out['grids'])} of {len(out['grids'])} solved grids")
    print(f"plans not compared (a grid failed or did not answer on its nodes, or the corners "
          f"differ): {len(out['skipped'])}", *(f"\n  plan {i} (corners {sorted(o)}): {why}"
                                                for why, i, o in out["skipped"]), sep="")
    print(f"{time.perf_counter() - start:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())

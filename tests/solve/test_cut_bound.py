"""The secant cuts of the stencil rows: a tighter lower bound that stays a lower bound.

Oracles: the discrete problem solved by brute force on a grid of values (tiny instances:
every combination checked against the rows, written here), polished by IPOPT on the plain
formulation (``oracles.ipopt_plain``), and multi-start IPOPT on a comfort plan's problem. A
lower bound must stay below every feasible travel time they find.
"""

from __future__ import annotations

import os
import warnings

import numpy as np
import pytest
from oracles import ipopt_plain

import speedplan as sp
import speedplan.solve.discrete as discrete
from speedplan.solve import DiscreteProblem, solve_problem
from speedplan.solve.cuts import secant_cuts

PATHS = os.path.join(os.path.dirname(__file__), "..", "..", "paths")


def _valley(seed: int) -> DiscreteProblem:
    """Six nodes through a valley of the speed bound, moving at both ends, tight jerk rows."""
    rng = np.random.default_rng(seed)
    n = 6
    s = np.concatenate(([0.0], np.cumsum(rng.uniform(0.5, 1.5, n - 1))))
    top = rng.uniform(2.0, 4.0)
    w_max = np.full(n, top)
    w_max[rng.integers(1, n - 1)] = top * rng.uniform(0.1, 0.5)
    w_max[0], w_max[-1] = rng.uniform(0.5, 1.0, 2) * top
    accel = rng.uniform(1.0, 4.0, n - 1)
    return DiscreteProblem(s=s, w_max=w_max, accel=accel, decel=accel.copy(),
                           jerk=rng.uniform(0.05, 0.5, n - 2), w_start=float(w_max[0]),
                           w_end=float(w_max[-1]))


def _feasible(p: DiscreteProblem, w: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    """Rows of ``w`` (one candidate per row) meeting every bound and row of ``p``."""
    d = np.diff(w, axis=1)
    ok = np.all(d <= p.accel * p.h + tol, axis=1) & np.all(-d <= p.decel * p.h + tol, axis=1)
    ok &= np.all(w[:, 1:-1] <= p.w_max[1:-1] + tol, axis=1) & np.all(w[:, 1:-1] > 0, axis=1)
    for family in p.stencil_families():
        c = family.coef
        load = c[:, 0] * w[:, :-2] + c[:, 1] * w[:, 1:-1] + c[:, 2] * w[:, 2:]
        ok &= np.all(np.abs(load) * np.sqrt(np.maximum(w[:, 1:-1], 0.0))
                     <= family.bound * (1 + 1e-9), axis=1)
    return ok


def _grid_points(p: DiscreteProblem, levels: int = 40) -> np.ndarray:
    """Every combination of ``levels`` values per interior node that meets ``p``'s rows."""
    grids = [np.linspace(p.w_max[i] / levels, p.w_max[i], levels) for i in range(1, p.n - 1)]
    mesh = np.meshgrid(*grids, indexing="ij")
    w = np.zeros((mesh[0].size, p.n))
    w[:, 1:-1] = np.column_stack([m.ravel() for m in mesh])
    w[:, 0], w[:, -1] = p.w_start, p.w_end
    return w[_feasible(p, w)]


def _best_feasible(p: DiscreteProblem, points: np.ndarray) -> float:
    """Least travel time over the grid's feasible ``points``, the ten best IPOPT-polished."""
    if points.shape[0] == 0:
        return np.inf
    times = np.sum(p.tau / np.sqrt(points[:, 1:-1]), axis=1)
    best = float(times.min())
    for k in np.argsort(times)[:10]:
        answer = ipopt_plain(p, points[k], {"tol": 1e-12, "constr_viol_tol": 1e-12,
                                            "bound_relax_factor": 0.0})
        if answer.success and _feasible(p, answer.w[None, :], tol=1e-10)[0]:
            best = min(best, p.travel_time(answer.w))
    return best


def _bounds(p: DiscreteProblem, monkeypatch: pytest.MonkeyPatch):
    """The solution without the cuts, and with them whatever its gap."""
    monkeypatch.setattr(discrete, "CUT_GAP", np.inf)
    plain = solve_problem(p, backend="clarabel")
    monkeypatch.setattr(discrete, "CUT_GAP", 0.0)
    return plain, solve_problem(p, backend="clarabel")


def test_the_cut_bound_stays_below_the_brute_force_optimum(monkeypatch):
    tighter = 0
    for seed in (7, 12, 14, 20, 21, 30, 36, 41, 59):
        p = _valley(seed)
        points = _grid_points(p)
        cuts = secant_cuts(p)  # no feasible point is cut
        assert all(cuts.violation(w) == 0.0 for w in points), seed
        plain, cut = _bounds(p, monkeypatch)
        assert not plain.exact
        assert cut.lower_bound <= _best_feasible(p, points) * (1 + 1e-9), seed
        assert cut.objective >= cut.lower_bound
        tighter += cut.lower_bound > plain.lower_bound * (1 + 1e-3)
    assert tighter >= 6  # the cuts bite on most of these valleys (without them: 0)


def test_nurbs_edge_with_comfort_limits_is_certified_within_one_percent():
    # The relaxation of this plan pays for tangential and lateral jerk excesses where the
    # curvature grows again after a knot of the NURBS (s = 8.8 m): its bound was 3.1 % below
    # the refined plan, whose multi-start refinement finds nothing better.
    path = sp.io.read_path(os.path.join(PATHS, "nurbs_edge.json"))
    lim = sp.Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5, j_lat_max=0.3, yaw_rate_max=0.4)
    profile = sp.plan(path, lim)
    assert profile.status == "refined"
    assert profile.solution.relaxation.cut_bound is not None
    assert 0.0 <= profile.gap <= 0.01


def test_the_cut_bound_of_a_comfort_plan_is_below_every_point_multistart_ipopt_finds(monkeypatch):
    from speedplan.model import PlanRequest, build_model

    path = sp.io.read_path(os.path.join(PATHS, "nurbs_edge.json"))
    lim = sp.Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5, j_lat_max=0.3, yaw_rate_max=0.4)
    (leg,) = build_model(PlanRequest.create(path, lim, n=30)).legs
    p = leg.problem
    plain, solution = _bounds(p, monkeypatch)
    assert solution.relaxation.cut_bound is not None
    assert solution.gap < 0.5 * plain.gap  # (3.0 % -> 1.0 %, measured)
    rng = np.random.default_rng(0)
    found = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for _ in range(6):
            w0 = solution.relaxation.w * rng.uniform(0.5, 1.0) * rng.uniform(0.9, 1.0, p.n)
            answer = ipopt_plain(p, w0, {"tol": 1e-10, "constr_viol_tol": 1e-10,
                                         "max_iter": 800})
            if answer.success and answer.violation_price <= 1e-8:
                found.append(p.travel_time(answer.w) * (1 + answer.violation_price))
    assert len(found) >= 3
    assert solution.lower_bound <= min(found) * (1 + 1e-9)


def test_a_cut_solve_stopped_early_still_bounds_the_plan_from_below():
    # Clarabel gets at most CUT_SECONDS (or as long as the solve before it) for the cuts; its
    # last iterate's multipliers then give the bound (weak duality). Whatever the iterate, a
    # bound must stay below every feasible travel time: the plan's own refined point, and
    # IPOPT's point on the plain formulation polished from it.
    from speedplan.model import PlanRequest, build_model
    from speedplan.solve.clarabel_ import solve_relaxation

    path = sp.io.read_path(os.path.join(PATHS, "nurbs_edge.json"))
    lim = sp.Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5, j_lat_max=0.3, yaw_rate_max=0.4)
    (leg,) = build_model(PlanRequest.create(path, lim)).legs
    p = leg.problem
    solution = solve_problem(p)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        polished = ipopt_plain(p, solution.w, {"tol": 1e-10, "constr_viol_tol": 1e-10})
    assert polished.success and polished.violation_price <= 1e-8
    feasible = min(solution.objective,
                   p.travel_time(polished.w) * (1 + polished.violation_price))
    relaxed = discrete._relaxed(p, "banded", True)
    cuts = secant_cuts(relaxed.unit).near(
        discrete._violating_nodes(relaxed.unit, relaxed.w_unit), discrete.CUT_PAD)
    stopped = solve_relaxation(relaxed.unit, cuts=cuts, time_limit=1e-3)
    assert stopped.status == "MaxTime"  # the case is exercised
    bounds = []
    for seconds in (1e-3, 3e-3, 1e-2, 3e-2, 10.0):
        cut = discrete._with_cuts(p, relaxed, solution.objective, seconds)
        assert cut.lower >= relaxed.lower
        assert cut.info.cut_bound is not None
        assert cut.info.cut_bound <= feasible * (1 + 1e-9), seconds
        bounds.append(cut.lower)
    assert bounds[-1] > relaxed.lower * (1 + 1e-3)  # solved to the end, the cuts bite

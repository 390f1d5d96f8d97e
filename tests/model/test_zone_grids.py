"""Slow zones on the default grid: resolved where they are, coarsened if no solver converges.

Found by ``benchmarks/fuzz_zones.py`` (seed 1, cases 55, 60, 111, 115): on paths with a slow
zone, both interior-point methods stalled (``NoProgress``, ``AlmostSolved`` at a law that
stops inside the leg) on fine default grids, and ``plan()`` raised ``SolverError`` on feasible
requests. The straight move below is the smallest reproduction found: a 1 m move through a
0.11 m/s zone, whose 6 783-node default grid neither backend solved. (Since the banded
method's progress test counts its residuals too, ``tests/solve/test_ipm_progress.py``, it solves
that grid; the coarser grids remain the next step where it gives up.)
"""

from __future__ import annotations

import importlib

import numpy as np
import pytest
from oracles import measure, no_jerk_lower_bound, ruckig_move, within_promise

from speedplan import Limits, Path, SpeedZone, plan
from speedplan.geometry import SpeedBound
from speedplan.model import PlanRequest, build_model
from speedplan.model.grid import CAPPED_GRADING, CRUISE_GRADING, GRADING, MIN_NODES
from speedplan.strategy import coarser_leg

plan_module = importlib.import_module("speedplan.plan")

LIM = Limits(v_max=2.6, a_max=0.406, a_lat_max=1.0, j_max=4.86)
ENTRY, EXIT, V_ZONE = 0.15, 0.6, 0.11


def _straight_with_zone() -> tuple[Path, SpeedZone]:
    path = Path.from_waypoints([[0.0, 0.0], [1.0, 0.0]], kind="polyline")
    zone = SpeedZone([(ENTRY, -1.0), (EXIT, -1.0), (EXIT, 1.0), (ENTRY, 1.0)], v_max=V_ZONE)
    return path, zone


def _assert_physical(lim: Limits, length: float, entry: float, exit_: float,
                     v_zone: float) -> None:
    """Plan a straight with one zone on the default grid and judge it by physics.

    Finite differences of the sampled trajectory, the speed inside the zone on the sampled
    positions themselves (not through the speed bound), and two independent references: no
    motion beats the exact no-jerk optimum, and a jerk-limited motion exists that takes
    ruckig's fastest move to the zone at its speed, crosses it at that speed and leaves it
    with ruckig's fastest stop (the optimum may enter braking and leave accelerating,
    dipping below the zone's speed: a little faster).
    """
    path = Path.from_waypoints([[0.0, 0.0], [length, 0.0]], kind="polyline")
    zone = SpeedZone([(entry, -1.0), (exit_, -1.0), (exit_, 1.0), (entry, 1.0)], v_max=v_zone)
    prof = plan(path, lim, zones=[zone])
    assert prof.status in ("optimal", "refined")
    m = measure(prof)
    assert within_promise(m), m
    traj = prof.at(np.linspace(0.0, prof.duration, 200_001))
    inside = (traj.x >= entry) & (traj.x <= exit_)
    assert traj.v[inside].max() <= v_zone * (1 + 1e-3)
    lower, _, _ = no_jerk_lower_bound(SpeedBound(path, lim, [zone]), length, lim.a_max,
                                      lim.a_decel)
    to_zone = ruckig_move(entry, lim, vf=v_zone).duration
    from_zone = ruckig_move(length - exit_, lim, v0=v_zone).duration
    assert to_zone is not None and from_zone is not None
    feasible = to_zone + (exit_ - entry) / v_zone + from_zone
    assert lower * (1 - 1e-9) <= prof.duration <= feasible * (1 + 1e-6)


@pytest.mark.slow
def test_slow_zone_on_the_default_grid_plans_within_physics() -> None:
    _assert_physical(LIM, 1.0, ENTRY, EXIT, V_ZONE)


def test_coarser_leg_has_half_the_nodes_and_keeps_the_grading() -> None:
    path, zone = _straight_with_zone()
    model = build_model(PlanRequest.create(path, LIM, zones=[zone]))
    (leg,) = model.legs
    factor = plan_module.COARSER_GRIDS[0]
    coarser = coarser_leg(model.request, leg, factor)
    assert coarser is not None
    assert coarser.problem.n <= factor * leg.problem.n + 2
    # Every step grows in proportion: a new step spans about 1 / factor old ones. Where the
    # old grid grades as a transition (by GRADING: the law's jerk error is the ratio minus
    # one) the new one stays as smooth, its ratio near the old one there to the power
    # 1 / factor; in cruise, where the cap binds, it grades by up to CAPPED_GRADING.
    s_old, s_new = leg.problem.s, coarser.problem.s
    old = np.diff(s_old)
    old_ratio = np.maximum(old[1:] / old[:-1], old[:-1] / old[1:])
    assert old_ratio.max() <= np.exp(CRUISE_GRADING) * 1.001
    h = np.diff(s_new)
    k = np.clip(np.searchsorted(s_old, s_new[1:-1]), 1, s_old.size - 2)  # old nodes there
    window = int(np.ceil(2.0 / factor)) + 1
    local = np.max([old_ratio[np.clip(k - 1 + d, 0, old_ratio.size - 1)]
                    for d in range(-window, window + 1)], axis=0)
    transition = local <= np.exp(GRADING) * 1.001
    assert transition.sum() > 100
    allowed = np.where(transition, np.maximum(local ** (1.0 / factor), np.exp(GRADING)),
                       np.exp(CAPPED_GRADING)) * 1.002
    assert np.all(h[1:] / h[:-1] <= allowed)
    assert np.all(h[:-1] / h[1:] <= allowed)
    assert coarser.problem.s[0] == 0.0 and coarser.problem.s[-1] == leg.problem.s[-1]


def test_user_grids_and_no_jerk_grids_are_never_coarsened() -> None:
    path, zone = _straight_with_zone()
    user = build_model(PlanRequest.create(path, LIM, zones=[zone], n=500))
    assert coarser_leg(user.request, user.legs[0], 0.5) is None
    free = Limits(v_max=2.6, a_max=0.406, a_lat_max=1.0, j_max=np.inf)
    no_jerk = build_model(PlanRequest.create(path, free, zones=[zone]))
    assert coarser_leg(no_jerk.request, no_jerk.legs[0], 0.5) is None
    model = build_model(PlanRequest.create(path, LIM, zones=[zone]))
    coarsest = coarser_leg(model.request, model.legs[0], 1e-9)
    assert coarsest is not None and coarsest.problem.n <= MIN_NODES + 2
    assert coarser_leg(model.request, coarsest, 0.5) is None


@pytest.mark.slow
def test_a_zone_slower_than_the_rest_phase_is_resolved() -> None:
    """A 3.45 cm/s zone whose jerk transitions (7 mm) are far shorter than the rest phase.

    ``fuzz_zones.py`` seed 1 case 45 (``limits_exceeded``, jerk 1.11x after three
    refinements): the default grid's floor, the first jerk phase from rest (9.9 m here),
    applied along the whole path and kept its steps at 0.12 m at the zone's edge. The floor
    now applies only on the stretches next to the ends.
    """
    lim = Limits(v_max=14.6, a_max=4.42, a_lat_max=2.2, j_max=0.886)
    _assert_physical(lim, 60.0, 38.0, 48.0, 0.0345)

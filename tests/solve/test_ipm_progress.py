"""The banded interior-point method keeps going while its residuals fall.

Found by ``benchmarks/fuzz_zones.py`` (seed 2, case 98): a 1.6 km G2 path through two zones
with a tight bend (0.25 m/s). The method gave up (``NoProgress``: 20 iterations without
halving the relative gap) on its default grid and on a half, a quarter and an eighth of it,
Clarabel solved the quarter grid only, and its refinement stalled both backends:
``limits_exceeded`` (jerk 1.09x) after 58 s. The gap there falls slowly for some 60
iterations while both residuals fall 30-fold, and the method then converges (117 iterations
on the 20 000-node grid). Progress now counts a halving of the gap or of either residual.
"""

from __future__ import annotations

import pytest
from oracles import measure, no_jerk_lower_bound, within_promise

from speedplan import Limits, Path, SpeedZone, plan
from speedplan.geometry import SpeedBound
from speedplan.model import PlanRequest, build_model
from speedplan.solve.banded import solve_relaxation_banded
from speedplan.strategy import coarser_leg

WAYPOINTS = [[43.83288979232604, 262.4054815071551], [206.12640702422482, 321.78604603717207],
             [177.5647570904682, 246.52852110317002], [519.0855872387414, 443.21044154192805],
             [310.8740578161603, 974.5521427956093], [-42.66578259466701, 861.9650582581844]]
BOXES = [((361.5523661458343, 762.4922953502481, 408.1367251524705, 809.0766543568842),
          0.26573915126154424),
         ((449.9212428418619, 551.6826376017466, 488.22744715264577, 589.9888419125305),
          3.0498278401118224)]
LIM = Limits(v_max=22.29760965066403, a_max=0.306527432763833, a_lat_max=0.4640642946520324,
             j_max=0.3210310832974421)


def _request() -> tuple[Path, list[SpeedZone]]:
    path = Path.from_waypoints(WAYPOINTS)
    zones = [SpeedZone([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], v_max=v)
             for (x0, y0, x1, y1), v in BOXES]
    return path, zones


def test_slow_gap_with_falling_residuals_is_not_no_progress() -> None:
    # An eighth of the default grid (2 501 nodes): NoProgress after 41 iterations before.
    path, zones = _request()
    model = build_model(PlanRequest.create(path, LIM, zones=zones))
    (leg,) = model.legs
    coarse = coarser_leg(model.request, leg, 1 / 8)
    assert coarse is not None
    res = solve_relaxation_banded(coarse.problem)
    assert res.status in ("Solved", "AlmostSolved")
    assert res.dual_objective <= res.primal_objective * (1 + 1e-12)


@pytest.mark.slow
def test_the_zone_path_plans_within_physics() -> None:
    path, zones = _request()
    prof = plan(path, LIM, zones=zones)
    assert prof.status in ("optimal", "refined"), prof.verification
    m = measure(prof)
    assert within_promise(m), m
    lower, _, _ = no_jerk_lower_bound(SpeedBound(path, LIM, zones), path.length, LIM.a_max,
                                      LIM.a_decel)
    assert prof.duration >= lower * (1 - 1e-9)

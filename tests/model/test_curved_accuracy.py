"""The default grid's duration on curved paths: within 1e-4 of the converged duration.

Oracles: ruckig's exact straight move (a circle from rest to rest), and, on the sample paths,
the Richardson extrapolation of the same plan on its default grid with every cell cut into
two and four equal steps.
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from oracles import ruckig_duration, subdivided_default_grids
from shared import LGV, examples

import speedplan as sp
from speedplan.geometry import Arc
from speedplan.io import read_path, read_zones

PATHS = os.path.join(os.path.dirname(__file__), "..", "..", "paths")
ACCURACY = 1e-4


def _limits(v_max: float) -> sp.Limits:
    return sp.Limits(v_max=v_max, a_max=LGV.a_max, a_lat_max=LGV.a_lat_max, j_max=LGV.j_max)


@pytest.mark.parametrize(("radius", "angle"), [(1.5, np.pi), (4.0, 2.0), (0.6, 5.0)])
def test_a_circle_from_rest_to_rest_takes_the_straight_move_under_its_lateral_speed(radius,
                                                                                     angle):
    # On an arc the speed bound is the constant sqrt(a_lat_max R): the move is ruckig's
    # straight move of the arc's length under that speed.
    v_arc = min(LGV.v_max, np.sqrt(LGV.a_lat_max * radius))
    profile = sp.plan(sp.Path.from_segments([Arc(radius=radius, angle=angle)]), LGV)
    exact = ruckig_duration(radius * angle, _limits(v_arc))
    assert profile.duration == pytest.approx(exact, rel=ACCURACY)


@settings(max_examples=examples(25), deadline=None)
@given(length=st.floats(-3.0, 3.5).map(lambda e: 10.0**e),    # 1 mm .. 3 km
       v_max=st.floats(-1.3, 1.6).map(lambda e: 10.0**e),     # 0.05 .. 40 m/s
       a_max=st.floats(-1.5, 0.8).map(lambda e: 10.0**e),
       j_max=st.floats(-1.5, 2.0).map(lambda e: 10.0**e))
def test_a_gentle_arc_from_rest_to_rest_is_never_faster_than_the_straight_move(length, v_max,
                                                                               a_max, j_max):
    # On an arc this gentle no lateral limit binds: ruckig's straight move is the exact
    # optimum. Before, the time law met the discrete speeds next to each rest by changing its
    # slope at the rest itself: moves made of their four jerk phases came out 2.3e-5 faster
    # than the optimum, their jerk at the rest 0.4 % above j_max.
    lim = sp.Limits(v_max=v_max, a_max=a_max, a_lat_max=1e6, j_max=j_max)
    radius = 1e5 * length
    profile = sp.plan(sp.Path.from_segments([Arc(radius=radius, angle=length / radius)]), lim)
    exact = ruckig_duration(length, lim)
    assert exact * (1 - 1e-6) <= profile.duration <= exact * (1 + ACCURACY)


def _converged(path: sp.Path, lim: sp.Limits, zones) -> tuple[float, float]:
    """Richardson's limit of the subdivided grids (second order) and its own spread."""
    durations = []
    for k in (2, 4):
        with subdivided_default_grids(k):
            durations.append(sp.plan(path, lim, zones=zones).duration)
    coarse, fine = durations
    return fine + (fine - coarse) / 3.0, abs(fine - coarse) / fine


COMFORT = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5, j_lat_max=0.3,
                    yaw_rate_max=0.4)


#: A road's comfort limits: the lateral-jerk limit binds at the joins of its clothoids.
ROAD_COMFORT = sp.Limits(v_max=15.0, a_max=2.0, a_lat_max=3.0, j_max=1.0, j_lat_max=0.3,
                         yaw_rate_max=0.4)


@pytest.mark.filterwarnings("ignore:the path.s curvature jumps")  # aisle_corners.csv: stops
@pytest.mark.parametrize(("name", "lim"), [
    ("u_turn.json", LGV), ("warehouse_loop.json", LGV), ("aisle_corners.csv", LGV),
    ("slow_zone.json", LGV), ("nurbs_edge.json", LGV), ("u_turn.json", COMFORT),
    ("warehouse_loop.json", COMFORT), ("aisle_corners.csv", COMFORT),
    ("nurbs_edge.json", COMFORT), ("road_s_curve.csv", ROAD_COMFORT)],
    ids=lambda x: x if isinstance(x, str) else "comfort" if x.j_lat_max < np.inf else "plain")
def test_sample_paths_plan_within_1e4_of_the_converged_duration(name, lim):
    # Before: 3.4e-4 (u_turn), 3.3e-4 (warehouse_loop), 9.8e-4 (aisle_corners), 2.8e-4
    # (slow_zone) above it: the node bounds took the least bound over both cells, O(h) where
    # it falls, and a kink of the bound (a clothoid onto an arc, a zone's edge) fell inside a
    # cell, at a place that changed with the grid. With comfort limits, the rate of the
    # curvature jumps at the NURBS's knots and at both ends of the millimetre lines between
    # the road's clothoids; where the lateral-jerk rows did not hold both sides of each, the
    # plans used the difference, by an amount that changed with the grid (nurbs_edge: grids
    # cut in 2 and 4 5.4e-4 apart; road_s_curve: the default grid 3e-4 under them).
    path = read_path(os.path.join(PATHS, name))
    zones = read_zones(os.path.join(PATHS, name)) or None
    duration = sp.plan(path, lim, zones=zones).duration
    converged, spread = _converged(path, lim, zones)
    assert spread < ACCURACY / 4  # the reference is converged far below the target
    assert duration == pytest.approx(converged, rel=ACCURACY)


#: A 9.3 m random G2 path (benchmarks/bench_curved_accuracy.py, seed 0, path 22) whose first
#: jerk phase from rest spans 9 nodes of its default grid.
SHORT_START = [[1.3208588733031048, 0.2409109281424442], [3.953885083750345, 0.13688215743100818],
               [3.7682392355531182, -1.7286390106421219],
               [1.1144593354485948, -0.09545382202795305], [3.770141214496522, 1.276711080249431]]


def test_a_first_jerk_phase_of_a_few_nodes_plans_within_1e4_of_the_converged_duration():
    # Before: 1.5e-4 faster than the converged duration, nearly all of it next to the two
    # rests (the law 0.3 % above the discrete speeds there).
    path = sp.Path.from_waypoints(SHORT_START, max_deviation=0.33334989303540935)
    lim = sp.Limits(v_max=5.280693495689563, a_max=2.5264876517971615,
                    a_lat_max=0.8189002297006358, j_max=1.2264414897265106)
    duration = sp.plan(path, lim).duration
    converged, spread = _converged(path, lim, None)
    assert spread < ACCURACY / 4
    assert duration == pytest.approx(converged, rel=ACCURACY)


def test_a_nurbs_plan_replans_from_its_own_states_to_the_same_arrival():
    # The rest of the path planned from a state read off the plan arrives when the plan does.
    # Before, 7.4e-4 and 1.1e-3 of the duration earlier from the first two states: the plan
    # let its lateral jerk straddle the NURBS's knots, where the curvature rate jumps, at
    # places that depend on the grid.
    path = read_path(os.path.join(PATHS, "nurbs_edge.json"))
    first = sp.plan(path, COMFORT)
    for t in np.linspace(0.1, 0.5, 3) * first.duration:
        state = first.at(t)
        again = sp.plan(path.sub(float(state.s[0])), COMFORT, v0=float(state.v[0]),
                        a0=float(state.a[0]))
        assert again.verification.ok
        assert t + again.duration == pytest.approx(first.duration, rel=ACCURACY), t


def test_a_spline_through_many_waypoints_plans_within_1e4_of_the_converged_duration():
    # The curvature rate jumps at every knot of a cubic spline, and the speed bound kinks
    # there. Before the knots were breakpoints of the bound, they fell inside cells, whose
    # node bounds lose O(h) of a kink: 5.8e-4 above the converged duration here.
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 1.0, 100)
    xy = np.column_stack((200.0 * t, 10.0 * np.sin(12.0 * t) + rng.normal(0.0, 0.05, t.size)))
    path = sp.Path.from_waypoints(xy, kind="spline")
    lim = sp.Limits(v_max=3.0, a_max=1.0, a_lat_max=1.0, j_max=1.0)
    assert path.rate_joins.size == t.size - 2
    duration = sp.plan(path, lim).duration
    converged, spread = _converged(path, lim, None)
    assert spread < ACCURACY / 4
    assert duration == pytest.approx(converged, rel=ACCURACY)

"""User grids (``n`` / ``ds``): graded at their ends (rests, moving states), judged by physics.

A uniform grid coarser than the first jerk phase from rest (``ℓ = j t³ / 6``) gives a law
whose jerk exceeds ``j_max`` there by about ``0.4 h / ℓ``; before the grading, ``plan()``
refined such grids after a first solve, and 22 of 150 random straight moves from rest on
coarse grids still ended ``limits_exceeded`` after three refinements.
"""

from __future__ import annotations

import importlib

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from oracles import PROMISED, measure, ruckig_duration, ruckig_move, within_promise
from shared import LGV, examples

import speedplan as sp
from speedplan.geometry import Line
from speedplan.model import PlanRequest, build_model
from speedplan.model.grid import END_PER_PHASE, GRADING, graded_ends

strategy = importlib.import_module("speedplan.strategy")


def _first_checks(path: sp.Path, lim: sp.Limits, **kw: object) -> list[sp.Verification]:
    """The checks of the laws of the model's own grid, before any refinement."""
    request = PlanRequest.create(path, lim, **kw)
    model = build_model(request)
    legs = tuple(strategy.solve_leg(leg) for leg in model.legs)
    profile = sp.SpeedProfile(path=path, limits=lim, legs=legs, speed_bound=model.bound,
                              request=request)
    return [profile.check_leg(i).verification for i in range(len(legs))]


@pytest.mark.parametrize("kw", [{"n": 1000}, {"ds": 0.12}])
def test_the_first_law_of_a_coarse_user_grid_keeps_the_jerk_at_the_stops(kw):
    # A 122 m serpentine (20 waypoints, G2 corners) at n=1000: before the grading the first
    # law's jerk was 1.12 j_max 0.4 m before the end (and after the start), so plan() solved
    # twice.
    pts = [(x, 3.0 * row) for row in range(10)
           for x in ((0.0, 10.0) if row % 2 == 0 else (10.0, 0.0))]
    path = sp.Path.from_waypoints(np.array(pts))
    checks = _first_checks(path, LGV, **kw)
    assert all(c.ok for c in checks), [c.ratios for c in checks]
    assert max(c.ratios["jerk"] for c in checks) <= 1.0 + PROMISED["jerk"]


def test_stops_inside_the_path_are_graded_too():
    # A stop splits the path into legs that each end (start) at rest.
    path = sp.Path.from_segments([Line(60.0)])
    checks = _first_checks(path, LGV, n=400, stops=[25.0])
    assert len(checks) == 2 and all(c.ok for c in checks), [c.ratios for c in checks]


def test_graded_ends_keeps_the_interior_and_grades_smoothly():
    s = np.linspace(0.0, 200.0, 1001)
    ell = 0.6
    g = graded_ends(s, ell, ell)
    steps = np.diff(g)
    assert g[0] == 0.0 and g[-1] == 200.0 and np.all(steps > 0)
    assert steps[0] <= ell / END_PER_PHASE * (1 + 1e-9)
    assert steps[-1] <= ell / END_PER_PHASE * (1 + 1e-9)
    ratio = steps[1:] / steps[:-1]
    assert ratio.max() <= 1.0 + 1.01 * GRADING and ratio.min() >= 1.0 / (1.0 + 1.01 * GRADING)
    inner = (s > 20.0) & (s < 180.0)
    assert np.isin(s[inner], g).all()  # the interior nodes are the user's
    # Only where the uniform step is too coarse; a moving end keeps its step.
    assert np.array_equal(graded_ends(s, 10 * END_PER_PHASE * 0.2, None), s)
    assert np.array_equal(graded_ends(s, None, None), s)


@settings(max_examples=examples(30), deadline=None)
@given(
    length=st.floats(-2.0, 3.5).map(lambda e: 10.0**e),      # 1 cm .. 3 km
    v_max=st.floats(-1.0, 1.5).map(lambda e: 10.0**e),       # 0.1 .. 30 m/s
    a_max=st.floats(-1.0, 0.7).map(lambda e: 10.0**e),
    j_max=st.floats(-1.3, 1.0).map(lambda e: 10.0**e),
    n=st.floats(1.5, 3.3).map(lambda e: int(10.0**e)),       # 31 .. 1995 nodes
    start=st.one_of(st.just((0.0, 0.0)),
                    st.tuples(st.floats(0.01, 1.0), st.floats(-1.0, 1.0))),
)
def test_straight_moves_on_user_grids_meet_the_limits_and_ruckig(length, v_max, a_max, j_max,
                                                                 n, start):
    # Before the grading of user grids, 34 of 200 such random moves (seed 1 of
    # benchmarks/fuzz_user_grids.py) ended limits_exceeded and 6 were refused although
    # ruckig moves them.
    lim = sp.Limits(v_max=v_max, a_max=a_max, a_lat_max=1.0, j_max=j_max)
    v0, a0 = start[0] * v_max, start[1] * a_max
    optimum = ruckig_move(length, lim, v0=v0, a0=a0).duration
    assume(optimum is not None)
    profile = sp.plan(sp.Path.from_segments([Line(length)]), lim, n=n, v0=v0, a0=a0)
    assert profile.status == "optimal"
    m = measure(profile)
    assert within_promise(m), m
    # Never faster than the optimum of the limits with their tolerances (what the
    # trajectory may reach); within 1e-3 of the optimum of the limits themselves.
    loose = sp.Limits(v_max=v_max * (1 + PROMISED["speed"]), a_max=a_max * (1 + PROMISED["accel"]),
                      a_lat_max=1.0, j_max=j_max * (1 + PROMISED["jerk"]))
    assert profile.duration >= ruckig_duration(length, loose, v0=v0, a0=a0) * (1 - 1e-12)
    assert profile.duration <= optimum * (1 + 1e-3)


@pytest.mark.parametrize("fraction", [2.225073858507e-311, 1e-12, 1e-10, -1e-10])
def test_a_rounding_level_start_acceleration_grades_a_user_grid_as_none(fraction):
    # A moving start read with an acceleration of rounding size. Sized by the time to remove
    # it, the grid's first steps would be 1.6 nm (1e-11 of the move), where w changes by
    # 1e-16 per node and the law's jerk (1.08-1.57 of j_max) depends on the relaxation's last
    # digits. Removing it takes no time worth a step of its own.
    lim = sp.Limits(v_max=0.4641588833612779, a_max=0.15482828285804393, a_lat_max=1.0,
                    j_max=1.0)
    path = sp.Path.from_segments([Line(161.39094296677285)])
    v0 = 0.0258101
    still = sp.plan(path, lim, n=1344, v0=v0)
    profile = sp.plan(path, lim, n=1344, v0=v0, a0=fraction * lim.a_max)
    assert profile.s[1] == still.s[1]
    assert profile.status == "optimal"
    assert within_promise(measure(profile))
    optimum = ruckig_move(161.39094296677285, lim, v0=v0, a0=fraction * lim.a_max).duration
    assert profile.duration == pytest.approx(optimum, rel=1e-6)

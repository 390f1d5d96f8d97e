"""Reversals (cusps), asked stops, span limits, lateral-jerk and yaw-rate limits in plan().

Oracles: ruckig's exact rest-to-rest optima for the straight pieces, finite differences of
the sampled trajectory in time (lateral jerk from the sampled lateral acceleration, yaw rate
from the sampled heading: the path's geometry, not the planner's formulas), and an
independent cvxpy formulation of the relaxation with lateral-jerk rows written from the
physics (``d(κ v²)/dt``) with the clothoid's curvature in closed form.
"""

from __future__ import annotations

import warnings

import cvxpy as cp
import numpy as np
import pytest
from oracles import PROMISED, ruckig_duration
from shared import LGV

import speedplan as sp
from speedplan import InfeasibleError, InvalidInputError, Limits, Path, SpanLimit, plan
from speedplan.geometry import Clothoid, Line
from speedplan.model import PlanRequest, build_model
from speedplan.solve import solve_problem

COMFORT = Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5, j_lat_max=0.3,
                 yaw_rate_max=0.4)
DT = 1e-3


def _widened(lim):
    """The limits widened by the README's tolerances."""
    return Limits(v_max=lim.v_max * (1 + PROMISED["speed"]),
                  a_max=lim.a_max * (1 + PROMISED["accel"]),
                  a_decel=lim.a_decel * (1 + PROMISED["accel"]), a_lat_max=lim.a_lat_max,
                  j_max=lim.j_max * (1 + PROMISED["jerk"]))


def _fd(traj, column):
    return np.diff(getattr(traj, column)) / np.diff(traj.t)


def _time_of(traj, s):
    return float(traj.t[np.argmin(np.abs(traj.s - s))])


@pytest.mark.parametrize(("drive_in", "back_out"), [(10.0, 6.0), (3.0, 3.0), (40.0, 0.5)])
def test_straight_drive_in_back_out_is_the_sum_of_two_rest_to_rest_optima(drive_in, back_out):
    path = Path.from_waypoints([[0, 0], [drive_in, 0], [drive_in - back_out, 0]])
    assert path.cusps.tolist() == pytest.approx([drive_in])
    profile = plan(path, LGV)
    reference = ruckig_duration(drive_in, LGV) + ruckig_duration(back_out, LGV)
    # Never faster than physics allows within the promised tolerances, and within 1e-4 of
    # the exact optimum (the continuous law may use the jerk tolerance: ~1e-5 faster).
    wide = _widened(LGV)
    assert profile.status == "optimal"
    assert profile.duration >= ruckig_duration(drive_in, wide) + ruckig_duration(back_out, wide)
    assert profile.duration == pytest.approx(reference, rel=1e-4)
    traj = profile.sample(DT)
    # At rest at the cusp, the direction flips there, the heading does not move.
    t_cusp = _time_of(traj, drive_in)
    state = profile.at([t_cusp])
    assert state.v[0] <= 1e-3 * LGV.v_max
    assert set(np.unique(traj.direction[traj.s < drive_in - 1e-6])) == {1.0}
    assert set(np.unique(traj.direction[traj.s > drive_in + 1e-6])) == {-1.0}
    assert np.abs(traj.heading).max() == 0.0
    assert traj.x[-1] == pytest.approx(drive_in - back_out, abs=1e-9)
    assert traj.y[-1] == pytest.approx(0.0, abs=1e-9)
    # Speed is the magnitude: the position moves back along x after the cusp.
    after = traj.s > drive_in + 1e-6
    assert np.all(np.diff(traj.x[after]) <= 1e-12)
    a_fd = _fd(traj, "v")
    assert np.abs(a_fd).max() <= LGV.a_max * (1 + PROMISED["accel"])
    assert np.abs(np.diff(a_fd) / DT).max() <= LGV.j_max * (1 + PROMISED["jerk"])


def test_forklift_reverses_into_the_rack_with_a_turn():
    # Down the aisle past the rack opening, then back into it, turning by 18°.
    path = Path.from_waypoints([[0, 0], [12, 0], [9, -1]], max_deviation=0.5)
    assert path.cusps.size == 1
    profile = plan(path, COMFORT)
    traj = profile.sample(DT)
    cusp = float(path.cusps[0])
    assert profile.at([_time_of(traj, cusp)]).v[0] <= 1e-3 * COMFORT.v_max
    assert traj.direction[0] == 1.0 and traj.direction[-1] == -1.0
    heading_steps = np.abs(np.diff(traj.heading))
    assert heading_steps.max() < 0.01  # the vehicle's heading is continuous through the cusp
    assert np.hypot(traj.x[-1] - 9, traj.y[-1] + 1) <= 1e-9
    assert profile.verification.ok, profile.verification.summary()


def test_a_cusp_too_close_for_the_moving_start_is_refused_where():
    path = Path.from_waypoints([[0, 0], [1, 0], [0, 0]])
    with pytest.raises(InfeasibleError, match=r"cusp at s=1 m") as info:
        plan(path, LGV, v0=2.0)
    assert info.value.constraint == "length"


def test_asked_stops_are_at_rest_and_cost_what_two_moves_cost():
    line = Path.from_segments([Line(20.0)])
    profile = plan(line, LGV, stops=[8.0])
    wide = _widened(LGV)
    assert profile.duration >= ruckig_duration(8.0, wide) + ruckig_duration(12.0, wide)
    assert profile.duration == pytest.approx(
        ruckig_duration(8.0, LGV) + ruckig_duration(12.0, LGV), rel=1e-4)
    traj = profile.sample(DT)
    assert profile.at([_time_of(traj, 8.0)]).v[0] <= 1e-3 * LGV.v_max
    for bad in ([0.0], [20.0], [-1.0], [25.0]):
        with pytest.raises(InvalidInputError, match="`stops` must lie strictly inside"):
            plan(line, LGV, stops=bad)


def test_span_limits_cap_speed_and_yaw_rate_over_their_stretch():
    path = Path.from_waypoints([[0, 0], [20, 0], [20, 10]], max_deviation=1.0)
    spans = [SpanLimit(5.0, 12.0, v_max=0.8), SpanLimit(12.0, path.length, yaw_rate_max=0.2)]
    profile = plan(path, LGV, spans=spans)
    traj = profile.sample(DT)
    inside = (traj.s >= 5.0) & (traj.s <= 12.0)
    assert traj.v[inside].max() <= 0.8 * (1 + PROMISED["speed"])
    assert traj.v[inside].max() >= 0.8 * 0.99  # and it does use the span's limit
    late = traj.s[:-1] >= 12.0
    yaw_fd = np.abs(_fd(traj, "heading"))
    assert yaw_fd[late].max() <= 0.2 * (1 + PROMISED["speed"])
    assert np.abs(traj.v[~inside]).max() > 1.0  # outside the span the vehicle is faster
    with pytest.raises(InvalidInputError, match="end > start"):
        SpanLimit(3.0, 2.0, v_max=1.0)
    with pytest.raises(InvalidInputError, match="beyond the path's length"):
        plan(path, LGV, spans=[SpanLimit(0.0, 1e3, v_max=1.0)])


@pytest.mark.parametrize("waypoints", [
    [[0, 0], [20, 0], [20, 6], [0, 6], [0, 12]],  # the serpentine aisle
    [[0, 0], [10, 0], [14, 4], [14, 12]],
])
def test_lateral_jerk_and_yaw_rate_limits_hold_in_finite_differences(waypoints):
    path = Path.from_waypoints(waypoints)
    plain = plan(path, LGV)
    comfort = plan(path, COMFORT)
    assert comfort.verification.ok, comfort.verification.summary()
    assert comfort.duration >= plain.duration  # comfort costs time, never gains it
    assert comfort.solution.lower_bound <= comfort.duration * (1 + 1e-9)
    assert comfort.status in ("optimal", "refined")
    traj = comfort.sample(DT)
    j_lat_fd = _fd(traj, "a_lat")
    yaw_fd = _fd(traj, "heading")
    assert np.abs(j_lat_fd).max() <= COMFORT.j_lat_max * (1 + PROMISED["jerk"])
    assert np.abs(yaw_fd).max() <= COMFORT.yaw_rate_max * (1 + PROMISED["speed"])
    # The limits bind: without them the same path is driven beyond both.
    loose = plain.sample(DT)
    assert np.abs(_fd(loose, "a_lat")).max() > COMFORT.j_lat_max
    assert np.abs(_fd(loose, "heading")).max() > COMFORT.yaw_rate_max


def test_a_tight_corner_at_a_low_lateral_jerk_limit_is_refined_until_it_holds():
    # A corner of a random G2 path (from benchmarks/lateral_exactness.py) driven slowly at
    # j_lat_max = 0.125: halving the flagged steps twice left the lateral jerk 5.3 % over
    # (limits_exceeded); rounds that refine by the size of the excess bring it within 5 %.
    pts = [[-2.364, -3.489], [7.517, 2.135], [7.228, 0.587], [14.778, -7.676],
           [18.946, -1.893], [24.93, -5.448]]
    lim = Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5, j_lat_max=0.125,
                 yaw_rate_max=0.95)
    profile = plan(Path.from_waypoints(pts, max_deviation=0.82), lim)
    assert profile.status == "refined", profile.verification.summary()
    j_lat_fd = _fd(profile.sample(DT), "a_lat")
    assert np.abs(j_lat_fd).max() <= lim.j_lat_max * (1 + PROMISED["jerk"])


def test_curvature_jump_with_a_lateral_jerk_limit_stops_there_and_says_so():
    path = Path.from_segments([Line(6.0), sp.geometry.Arc(radius=5.0, angle=1.0), Line(6.0)])
    with pytest.warns(sp.SpeedplanWarning, match=r"curvature jumps at s = 6, 11 m.*kind='g2'"):
        profile = plan(path, COMFORT)
    traj = profile.sample(DT)
    for s in (6.0, 11.0):
        assert profile.at([_time_of(traj, s)]).v[0] <= 1e-3 * COMFORT.v_max
    assert np.abs(_fd(traj, "a_lat")).max() <= COMFORT.j_lat_max * (1 + PROMISED["jerk"])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        plan(path, LGV)  # no lateral-jerk limit: no stop, no warning
        plan(Path.from_waypoints([[0, 0], [20, 0], [20, 6]]), COMFORT)  # G2: none


def _cvxpy_lateral_relaxation(s, w_max, a_max, j_max, kappa, rate, j_lat):
    """The paper's relaxation on a uniform grid plus lateral rows written from the physics."""
    n = s.size
    h = s[1] - s[0]
    w, t = cp.Variable(n), cp.Variable(n - 2)
    cons = [w >= 0, w <= w_max, w[0] == 0, w[-1] == 0,
            cp.abs(w[1:] - w[:-1]) <= 2 * a_max * h]
    wi = w[1:-1]
    cons.append(t >= h * cp.power(wi, -0.5))
    # jerk = (w''/2) v: |w''| sqrt(w) <= 2 j_max, relaxed with t >= h / sqrt(w).
    d2 = (w[2:] - 2 * wi + w[:-2]) / h**2
    cons += [d2 <= 2 * j_max * t / h, -d2 <= 2 * j_max * t / h]
    # d(κ w)/ds at the node, times sqrt(w): κ' w + κ (w_{i+1} - w_{i-1}) / (2h).
    lat = cp.multiply(rate, wi) + cp.multiply(kappa, (w[2:] - w[:-2]) / (2 * h))
    cons += [lat <= j_lat * t / h, -lat <= j_lat * t / h]
    # The same at each cell's midpoint with the one-sided slope, held with sqrt(w) of both
    # ends (t of the cell's interior end nodes).
    mid = 0.5 * (s[:-1] + s[1:])
    k_mid = np.interp(mid, s[1:-1], kappa, left=np.nan, right=np.nan)
    k_mid[0], k_mid[-1] = kappa[0] - 0.5 * (kappa[1] - kappa[0]), \
        kappa[-1] + 0.5 * (kappa[-1] - kappa[-2])  # κ is linear in s on a clothoid
    r_mid = np.concatenate(([rate[0]], rate))
    lat_mid = (cp.multiply(r_mid, 0.5 * (w[1:] + w[:-1]))
               + cp.multiply(k_mid, (w[1:] - w[:-1]) / h))
    for cells, nodes in ((slice(1, n - 1), slice(None)), (slice(0, n - 2), slice(None))):
        cons += [lat_mid[cells] <= j_lat * t[nodes] / h, -lat_mid[cells] <= j_lat * t[nodes] / h]
    prob = cp.Problem(cp.Minimize(cp.sum(t)), cons)
    prob.solve(solver=cp.CLARABEL, tol_gap_abs=1e-10, tol_gap_rel=1e-10, tol_feas=1e-10)
    return prob.value


def test_lateral_rows_match_an_independent_relaxation_on_a_clothoid():
    k1, length, n = 0.4, 12.0, 121
    path = Path.from_segments([Clothoid(length, 0.0, k1)])
    lim = Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5, j_lat_max=0.2)
    s = np.linspace(0.0, length, n)
    kappa = k1 * s[1:-1] / length  # the clothoid's curvature, linear in s
    rate = np.full(n - 2, k1 / length)
    w_max = np.minimum(lim.v_max**2, lim.a_lat_max / np.maximum(k1 * s / length, 1e-300))
    (leg,) = build_model(PlanRequest.create(path, lim, n=n, standstill="free")).legs
    # The speed the lateral-jerk rows allow where braking (at most 2 a_decel in w') eases the
    # growing curvature: sqrt(w) (κ' w - κ 2 a_decel) <= j_lat_max, the largest root.
    caps = np.array([max(np.roots([r, 0.0, -k * 2 * lim.a_decel, -lim.j_lat_max]).real) ** 2
                     for k, r in zip(kappa, rate, strict=True)])
    got = leg.problem.w_max
    # The node bounds: the chord of every cell under the bound (read 64 times per cell; the
    # model reads it 8 times, which leaves a convex bound up to |b''| (h/8)² / 8 above the
    # chord between its readings; b = a_lat_max L / (k1 s) here), at most the bound at the
    # node and the caps, and below them by no more than the bound's curvature allows,
    # |b''| h²; the minimum over a node's two cells loses |b'| h instead.
    h = s[1] - s[0]
    theta = np.linspace(0.0, 1.0, 65)
    q = s[:-1, None] + h * theta
    chord = got[:-1, None] + (got[1:] - got[:-1])[:, None] * theta
    bound = np.minimum(lim.v_max**2, lim.a_lat_max * length / (k1 * np.maximum(q, 1e-300)))
    curvature = 2 * lim.a_lat_max * length / (k1 * np.maximum(s - h, h) ** 3)
    assert np.all(chord <= bound + (curvature[:-1, None] * (h / 8) ** 2 / 8 + 1e-12))
    upper = w_max.copy()
    upper[1:-1] = np.minimum(upper[1:-1], caps)
    assert np.all(got <= upper * (1 + 1e-8))
    assert np.all(got >= upper * (1 - 1e-8) - curvature * h**2)
    assert np.sum(got - _node_min(upper)) > 0.5  # well above the minimum over the cells
    reference = _cvxpy_lateral_relaxation(s, leg.problem.w_max, lim.a_max, lim.j_max, kappa,
                                          rate, lim.j_lat_max)
    sol = solve_problem(leg.problem)  # the lateral rows bind: refined, with its bound
    assert sol.lower_bound == pytest.approx(reference, rel=1e-7)
    assert sol.status == "refined" and sol.objective >= reference * (1 - 1e-9)
    assert leg.problem.jerk_violation(sol.w) <= leg.problem.jerk_tol


def _node_min(w):
    """The bound the model takes at each node: the minimum over its two neighbouring cells
    (monotone here, so the smaller neighbour)."""
    out = w.copy()
    out[:-1] = np.minimum(out[:-1], w[1:])
    out[1:] = np.minimum(out[1:], w[:-1])
    return out

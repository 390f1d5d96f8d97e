"""Turning on the spot: where a route's heading must change on a node, the vehicle stops and
rotates, and that time is in the node times and the trajectory.

Oracles: ruckig's time-optimal rest-to-rest rotation (speed = yaw rate, acceleration = yaw
acceleration, no jerk limit) and straight moves, and finite differences of the sampled
trajectory; never the planner's own checks.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from oracles import ruckig_duration, ruckig_turn
from shared import LGV

from speedplan import InvalidInputError, Limits, Route, plan_route
from speedplan.core.limits import DEFAULT_YAW_ACC
from speedplan.route import RouteProfile, RouteTurn
from speedplan.timing.rotation import Turn

DT = 0.01


def _node(i, x, y, theta=None, deviation=0.0, deviation_theta=None):
    pos = {"x": x, "y": y, "mapId": "hall", "allowedDeviationXY": deviation}
    if theta is not None:
        pos["theta"] = theta
    if deviation_theta is not None:
        pos["allowedDeviationTheta"] = deviation_theta
    return {"nodeId": f"n{i}", "sequenceId": 2 * i, "released": True, "nodePosition": pos,
            "actions": []}


def _edge(i, **fields):
    return {"edgeId": f"e{i}", "sequenceId": 2 * i + 1, "released": True,
            "startNodeId": f"n{i}", "endNodeId": f"n{i + 1}", "actions": [], **fields}


def _order(nodes, edges):
    return {"headerId": 0, "timestamp": "2024-05-06T08:00:00.00Z", "version": "2.0.0",
            "manufacturer": "ExampleAGV", "serialNumber": "LGV-0042", "orderId": "o",
            "orderUpdateId": 0, "nodes": nodes, "edges": edges}


def square_corner(theta_end=None, rate=0.3):
    """n0 (0,0) -> n1 (10,0) -> n2 (10,10); the corner at n1 may not be cut."""
    nodes = [_node(0, 0, 0), _node(1, 10, 0), _node(2, 10, 10, theta=theta_end)]
    return _order(nodes, [_edge(0, maxRotationSpeed=rate), _edge(1, maxRotationSpeed=rate)])


def assert_turns_physically(profile, rate_max, acc_max, dt=DT):
    """The sampled trajectory: heading continuous, yaw rate and yaw acceleration in their
    limits (finite differences), standing still while the heading turns."""
    traj = profile.sample(dt)
    step = np.diff(traj.t)
    rate = np.diff(traj.heading) / step
    assert np.max(np.abs(rate)) <= rate_max * (1 + 1e-6)
    acc = np.diff(rate) / (0.5 * (step[:-1] + step[1:]))  # rates sit mid-step
    assert np.max(np.abs(acc)) <= acc_max * (1 + 1e-6)
    turning = (np.abs(traj.yaw_rate) > 0) & (traj.curvature == 0)
    assert np.all(traj.v[turning] == 0)
    return traj


def test_a_corner_that_may_not_be_cut_costs_the_time_to_turn():
    route = Route.from_vda5050(square_corner())
    profile = plan_route(route, LGV)
    straight = ruckig_duration(10.0, LGV)
    turn = ruckig_turn(math.pi / 2, 0.3, DEFAULT_YAW_ACC)
    assert turn > (math.pi / 2) / 0.3  # at least 5.24 s at 0.3 rad/s
    arrive, leave = profile.node_times, profile.node_leave_times
    assert arrive[1] == pytest.approx(straight, rel=1e-3)
    assert leave[1] - arrive[1] == pytest.approx(turn, rel=1e-9)
    assert arrive[2] == pytest.approx(straight + turn + straight, rel=1e-3)
    assert profile.duration == pytest.approx(arrive[2], abs=1e-12)
    traj = assert_turns_physically(profile, 0.3, DEFAULT_YAW_ACC)
    during = (traj.t > arrive[1] + DT) & (traj.t < leave[1] - DT)
    assert np.all(traj.v[during] == 0)
    np.testing.assert_allclose(traj.x[during], 10.0, atol=1e-9)
    np.testing.assert_allclose(traj.y[during], 0.0, atol=1e-9)
    assert traj.heading[0] == pytest.approx(0.0, abs=1e-12)
    assert traj.heading[-1] == pytest.approx(math.pi / 2, abs=1e-9)


def test_a_node_theta_at_the_end_is_reached_on_the_node():
    profile = plan_route(Route.from_vda5050(square_corner(theta_end=math.pi)), LGV)
    turn = ruckig_turn(math.pi / 2, 0.3, DEFAULT_YAW_ACC)
    assert profile.duration - profile.node_times[2] == pytest.approx(turn, rel=1e-9)
    traj = assert_turns_physically(profile, 0.3, DEFAULT_YAW_ACC)
    assert math.remainder(traj.heading[-1] - math.pi, 2 * math.pi) == pytest.approx(0, abs=1e-9)
    assert traj.v[-1] == 0


@pytest.mark.parametrize(("tolerance", "turns"), [(None, True), (0.1, True), (2.0, False)])
def test_a_node_theta_within_its_allowed_deviation_needs_no_turn(tolerance, turns):
    """On a straight pass-through node: theta 0.5 rad off the path stops the vehicle and turns it
    there and back, unless allowedDeviationTheta covers the difference."""
    nodes = [_node(0, 0, 0), _node(1, 10, 0, theta=0.5, deviation_theta=tolerance),
             _node(2, 20, 0)]
    route = Route.from_vda5050(_order(nodes, [_edge(0), _edge(1)]))
    profile = plan_route(route, LGV)
    if not turns:
        assert profile.turns == () and route.stop_s.tolist() == [0.0, 20.0]
        return
    assert route.stop_s.tolist() == [0.0, 10.0, 20.0]
    assert [round(t.turn.angle, 12) for t in profile.turns] == [0.5, -0.5]
    # No maxRotationSpeed and no yaw_rate_max: the yaw acceleration alone bounds the turn.
    turn = ruckig_turn(0.5, np.inf, DEFAULT_YAW_ACC)
    assert profile.node_leave_times[1] - profile.node_times[1] == pytest.approx(2 * turn,
                                                                                rel=1e-6)
    traj = assert_turns_physically(profile, np.inf, DEFAULT_YAW_ACC)
    on_node = (np.abs(traj.x - 10.0) < 1e-9) & (traj.v == 0)
    assert np.max(traj.heading[on_node]) == pytest.approx(0.5, abs=DEFAULT_YAW_ACC * DT**2)
    between = profile.at(profile.turn_times[1])  # the first turn's end: theta met, at rest
    assert between.heading[0] == pytest.approx(0.5, abs=1e-12) and between.yaw_rate[0] == 0


def test_limits_rotation_fields_bound_the_turn():
    lim = Limits(2, 1, 1, 0.5, yaw_rate_max=0.2, yaw_acc_max=0.4)
    profile = plan_route(Route.from_vda5050(square_corner(rate=0.3)), lim)
    (turn,) = profile.turns
    assert turn.rate_limit == 0.2
    assert turn.duration == pytest.approx(ruckig_turn(math.pi / 2, 0.2, 0.4), rel=1e-9)
    assert_turns_physically(profile, 0.2, 0.4)
    check = profile.verify()
    assert check.ok and check.ratios["yaw_acc"] == pytest.approx(1.0)
    assert check.ratios["yaw_rate"] == pytest.approx(1.0)


def test_verify_reports_a_turn_beyond_its_limits():
    profile = plan_route(Route.from_vda5050(square_corner()), LGV)
    (turn,) = profile.turns
    fast = RouteTurn(turn.node, turn.s, Turn(turn.turn.start, turn.turn.angle, 0.6, 3.0), 0.3)
    forged = RouteProfile(profile.route, profile.legs, profile.leg_starts, turns=(fast,))
    assert set(forged.verify().violations) == {"yaw_rate", "yaw_acc"}


def test_heading_stays_continuous_round_a_loop_of_corners():
    """Four left turns: the heading runs on to 2π instead of jumping back."""
    pts = [(0, 0), (10, 0), (10, 10), (0, 10), (0, 0.5)]
    nodes = [_node(i, x, y) for i, (x, y) in enumerate(pts)]
    profile = plan_route(Route.from_vda5050(_order(nodes, [_edge(i) for i in range(4)])), LGV)
    assert len(profile.turns) == 3
    traj = assert_turns_physically(profile, np.inf, DEFAULT_YAW_ACC)
    assert traj.heading[-1] == pytest.approx(1.5 * math.pi, abs=1e-9)
    assert np.all(np.diff(profile.node_times) > 0)
    assert np.all(profile.node_leave_times >= profile.node_times)


def test_reversing_after_driving_forward_along_the_same_line_turns_round():
    """e1 continues e0's direction but is driven backwards: the vehicle turns by π first."""
    nodes = [_node(0, 0, 0), _node(1, 5, 0), _node(2, 10, 0)]
    edges = [_edge(0), _edge(1, orientation=math.pi)]
    profile = plan_route(Route.from_vda5050(_order(nodes, edges)), LGV)
    (turn,) = profile.turns
    assert abs(turn.turn.angle) == pytest.approx(math.pi)
    traj = assert_turns_physically(profile, np.inf, DEFAULT_YAW_ACC)
    assert traj.direction[-1] == -1
    assert math.remainder(traj.heading[-1] - math.pi, 2 * math.pi) == pytest.approx(0, abs=1e-9)


def test_a_start_heading_off_the_first_edge_turns_before_leaving():
    profile = plan_route(Route.from_vda5050(square_corner()), LGV, heading0=-1.0)
    first = profile.turns[0]
    assert first.node == 0 and first.turn.angle == pytest.approx(1.0)
    assert profile.node_times[0] == 0 and profile.node_leave_times[0] == pytest.approx(
        ruckig_turn(1.0, 0.3, DEFAULT_YAW_ACC), rel=1e-9)


@pytest.mark.parametrize("bad", [0.0, -1.0, np.inf, np.nan])
def test_yaw_acc_max_must_be_positive_and_finite(bad):
    with pytest.raises(InvalidInputError, match="yaw_acc_max"):
        Limits(2, 1, 1, 0.5, yaw_acc_max=bad)


@pytest.mark.parametrize(("angle", "rate", "acc", "jerk"), [
    (math.pi / 2, 0.3, 1.0, np.inf), (math.pi / 2, 0.3, 1.0, 2.0), (0.1, 0.3, 1.0, 2.0),
    (0.01, 0.3, 1.0, 2.0), (3.0, 1.0, 0.5, 0.3), (3.0, np.inf, 0.5, 0.3),
    (-2.0, 0.8, 0.5, 5.0), (math.pi, np.inf, 1.0, np.inf),
])
def test_turns_take_the_time_optimal_rest_to_rest_time(angle, rate, acc, jerk):
    turn = Turn(0.3, angle, rate, acc, jerk)
    assert turn.duration == pytest.approx(ruckig_turn(angle, rate, acc, jerk), rel=1e-9)
    t = np.linspace(0.0, turn.duration, 40_001)
    heading, yaw_rate, yaw_acc = turn.at(t)
    assert heading[0] == 0.3 and heading[-1] == 0.3 + angle and yaw_rate[-1] == 0
    step = t[1] - t[0]
    fd_rate = np.diff(heading) / step
    assert np.max(np.abs(fd_rate)) <= min(rate, 1e300) * (1 + 1e-9)
    fd_acc = np.diff(fd_rate) / step
    assert np.max(np.abs(fd_acc)) <= acc * (1 + 1e-6)
    # The returned rate and acceleration are the heading's derivatives ...
    np.testing.assert_allclose(fd_rate, 0.5 * (yaw_rate[1:] + yaw_rate[:-1]), atol=acc * step)
    if np.isfinite(jerk):  # ... and the acceleration changes no faster than the jerk limit
        np.testing.assert_allclose(np.diff(yaw_rate) / step, 0.5 * (yaw_acc[1:] + yaw_acc[:-1]),
                                   atol=jerk * step)
        assert np.max(np.abs(np.diff(yaw_acc) / step)) <= jerk * (1 + 1e-9)


def test_a_yaw_jerk_limit_makes_the_turns_s_curves():
    lim = Limits(2, 1, 1, 0.5, yaw_acc_max=1.0, yaw_jerk_max=0.5)
    profile = plan_route(Route.from_vda5050(square_corner()), lim)
    (turn,) = profile.turns
    assert turn.duration == pytest.approx(ruckig_turn(math.pi / 2, 0.3, 1.0, 0.5), rel=1e-9)
    assert turn.duration > ruckig_turn(math.pi / 2, 0.3, 1.0)
    traj = assert_turns_physically(profile, 0.3, 1.0)
    dt = np.diff(traj.t)
    rate = np.diff(traj.heading) / dt
    acc = np.diff(rate) / dt[1:]
    on = (traj.t[2:-1] > profile.turn_times[0]) & (traj.t[2:-1] < profile.node_leave_times[1])
    assert np.max(np.abs(np.diff(acc) / dt[2:])[on]) <= 0.5 * (1 + 1e-2)  # 10 ms samples
    check = profile.verify()
    assert check.ok and check.ratios["yaw_jerk"] == pytest.approx(1.0, rel=1e-3)
    assert "yaw_jerk" not in plan_route(Route.from_vda5050(square_corner()), LGV).verify().ratios


@pytest.mark.parametrize("bad", [0.0, -1.0, np.nan])
def test_yaw_jerk_max_must_be_positive(bad):
    with pytest.raises(InvalidInputError, match="yaw_jerk_max"):
        Limits(2, 1, 1, 0.5, yaw_jerk_max=bad)


def test_standing_between_nodes_off_the_path_the_vehicle_turns_onto_it_first():
    route = Route.from_vda5050(square_corner())
    profile = plan_route(route, LGV, start_s=4.0, heading0=0.5)
    first = profile.turns[0]
    assert first.node == -1 and first.s == 4.0 and first.turn.angle == pytest.approx(-0.5)
    arrive = profile.node_times
    assert np.isnan(arrive[0])
    assert arrive[1] == pytest.approx(first.duration + ruckig_duration(6.0, LGV), rel=1e-3)
    assert arrive[2] == pytest.approx(profile.node_leave_times[1] + ruckig_duration(10.0, LGV),
                                      rel=1e-3)
    assert_turns_physically(profile, 0.3, DEFAULT_YAW_ACC)
    with pytest.raises(InvalidInputError, match="heading0"):
        plan_route(route, LGV, start_s=4.0, v0=0.5, heading0=0.5)

"""plan_route(): VDA 5050 orders end to end — node times, edge limits, stops, order updates.

Oracles: the order's own numbers (edge lengths from hypot and the quarter circle's π R / 2,
speed limits), ruckig's exact optima for straight stop-to-stop legs, and finite differences of
the sampled (and stitched) trajectories; never the planner's own checks.
"""

from __future__ import annotations

import math
import warnings
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from oracles import PROMISED, ruckig_duration
from shared import LGV

from speedplan import InvalidInputError, Route, plan_route

HARD = {"actionType": "pick", "actionId": "pick-1", "blockingType": "HARD"}
R = 5.0  # the arc edge's radius
ARC_LIMIT = 0.8


def _node(i, x, y, version, actions=(), deviation=None):
    pos = {"x": x, "y": y, "mapId": "hall"}
    if deviation is not None:
        if version.startswith("2"):
            pos["allowedDeviationXy"] = deviation
        else:
            pos["allowedDeviationXY"] = {"a": deviation, "b": deviation, "theta": 0.0}
    return {"nodeId": f"N{i}", "sequenceId": 2 * i, "released": True, "nodePosition": pos,
            "actions": list(actions)}


def _edge(i, version, v_max=None, trajectory=None):
    e = {"edgeId": f"E{i}", "sequenceId": 2 * i + 1, "released": True, "actions": []}
    if version.startswith("2"):
        e |= {"startNodeId": f"N{i}", "endNodeId": f"N{i + 1}"}
    if v_max is not None:
        e["maxSpeed" if version.startswith("2") else "maximumSpeed"] = v_max
    if trajectory is not None:
        e["trajectory"] = trajectory
    return e


def three_edge_order(version="2.0.0"):
    """Line (0,0)->(10,0); quarter circle R=5 to (15,5) at ARC_LIMIT; line to (15,15).

    A HARD action on N1, the node between the first line and the arc.
    """
    w = math.sqrt(0.5)
    arc = {"degree": 2, "knotVector": [0, 0, 0, 1, 1, 1],
           "controlPoints": [{"x": 10.0, "y": 0.0, "weight": 1.0},
                             {"x": 15.0, "y": 0.0, "weight": w},
                             {"x": 15.0, "y": 5.0, "weight": 1.0}]}
    if version.startswith("3"):  # lines as controlPoints-only trajectories (3.0 defaults)
        line1 = {"controlPoints": [{"x": 0.0, "y": 0.0}, {"x": 10.0, "y": 0.0}]}
        line2 = {"controlPoints": [{"x": 15.0, "y": 5.0}, {"x": 15.0, "y": 15.0}]}
    else:
        line1 = line2 = None
    return {"headerId": 1, "timestamp": "2026-12-01T00:00:00.00Z", "version": version,
            "manufacturer": "m", "serialNumber": "s", "orderId": "o-3", "orderUpdateId": 0,
            "nodes": [_node(0, 0.0, 0.0, version), _node(1, 10.0, 0.0, version, [HARD]),
                      _node(2, 15.0, 5.0, version), _node(3, 15.0, 15.0, version)],
            "edges": [_edge(0, version, trajectory=line1),
                      _edge(1, version, v_max=ARC_LIMIT, trajectory=arc),
                      _edge(2, version, trajectory=line2)]}


def _fd_jerk(traj):
    dt = np.diff(traj.t)
    a = np.diff(traj.v) / dt
    return np.diff(a) / dt[1:]


def test_three_edge_order_end_to_end():
    route = Route.from_vda5050(three_edge_order())
    assert route.length == pytest.approx(20.0 + math.pi * R / 2, rel=1e-9)
    profile = plan_route(route, LGV)
    times = profile.node_times
    assert times[0] == 0.0 and times[-1] == pytest.approx(profile.duration, rel=1e-12)
    assert np.all(np.diff(times) > 0)
    traj = profile.sample(1e-3)
    # Stopped on the blocking node N1, at its time.
    assert profile.at([times[1]]).v[0] <= 1e-3 * LGV.v_max
    assert traj.x[np.argmin(np.abs(traj.t - times[1]))] == pytest.approx(10.0, abs=1e-3)
    # The arc edge's speed limit, and it is used.
    on_arc = traj.edge == 1
    assert traj.v[on_arc].max() <= ARC_LIMIT * (1 + PROMISED["speed"])
    assert traj.v[on_arc].max() >= 0.99 * ARC_LIMIT
    # Drives through N2 (no stop: the heading is continuous there), faster on the last line.
    assert profile.at([times[2]]).v[0] >= 0.9 * ARC_LIMIT
    assert traj.v[traj.edge == 2].max() > 1.5
    # The first leg is a straight rest-to-rest move: ruckig's optimum.
    assert profile.legs[0].duration == pytest.approx(ruckig_duration(10.0, LGV), rel=1e-4)
    uniform = profile.at(np.arange(0.0, profile.duration, 1e-3))
    assert np.abs(_fd_jerk(uniform)).max() <= LGV.j_max * (1 + PROMISED["jerk"])
    assert profile.verification.ok
    # The trajectory ends on the last node; the export carries the node times.
    assert (traj.x[-1], traj.y[-1]) == (pytest.approx(15.0, abs=1e-9),
                                        pytest.approx(15.0, abs=1e-9))
    meta = traj.metadata
    assert list(meta["node_ids"]) == ["N0", "N1", "N2", "N3"]
    assert list(meta["node_times"]) == pytest.approx(times.tolist(), rel=1e-15)
    header = traj.units
    assert list(header)[-1] == "edge"


def test_the_same_order_in_3_0_form_gives_the_same_plan():
    p2 = plan_route(Route.from_vda5050(three_edge_order("2.0.0")), LGV)
    p3 = plan_route(Route.from_vda5050(three_edge_order("3.0.0")), LGV)
    assert p3.duration == pytest.approx(p2.duration, rel=1e-9)
    np.testing.assert_allclose(p3.node_times, p2.node_times, rtol=1e-9)


def test_corners_between_straight_edges_are_rounded_within_the_node_deviation():
    def order(deviation):
        v = "2.0.0"
        return {"version": v, "nodes": [
            _node(0, 0.0, 0.0, v), _node(1, 12.0, 0.0, v, deviation=deviation),
            _node(2, 12.0, 9.0, v, deviation=deviation), _node(3, 0.0, 9.0, v)],
            "edges": [_edge(0, v), _edge(1, v), _edge(2, v)]}

    sharp = Route.from_vda5050(order(0.0))
    assert sharp.stop_s.size == 4  # stops at both corners: the vehicle turns on the spot
    round_ = Route.from_vda5050(order(0.3))
    assert round_.stop_s.tolist() == [0.0, pytest.approx(round_.length)]
    assert round_.rounded_nodes == (1, 2)
    path = round_.path
    s = np.linspace(0.0, path.length, 20001)
    xy = path.point(s)
    for k, (x, y) in ((1, (12.0, 0.0)), (2, (12.0, 9.0))):
        gap = np.hypot(xy[:, 0] - x, xy[:, 1] - y)
        assert gap.min() <= 0.3 + 1e-6  # (1 mm samples: within 1e-6 of the nearest point)
        assert path.point(round_.node_s[k]) == pytest.approx([
            xy[np.argmin(gap), 0], xy[np.argmin(gap), 1]], abs=1e-3)
    assert np.abs(np.diff(path.curvature(s))).max() < 0.05  # G2: no curvature steps
    profile = plan_route(round_, LGV)
    assert np.all(np.diff(profile.node_times) > 0)
    assert profile.at(profile.node_times[1:3]).v.min() > 0.2  # drives through the corners
    assert profile.duration < plan_route(sharp, LGV).duration


def test_order_update_while_driving_continues_smoothly():
    route = Route.from_vda5050(three_edge_order())
    first = plan_route(route, LGV)
    dt = 1e-3
    # Mid last edge, on the sampling grid so that the stitched samples stay uniform.
    t_switch = round(0.5 * (first.node_times[2] + first.node_times[3]) / dt) * dt
    state = first.at([t_switch])
    s0, v0, a0 = float(state.s[0]), float(state.v[0]), float(state.a[0])
    update = plan_route(route, LGV, start_s=s0, v0=v0, a0=a0)
    assert np.isnan(update.node_times[:3]).all()
    assert update.at([0.0]).s[0] == pytest.approx(s0, abs=1e-9)
    # Never slower than continuing the old plan (a feasible continuation), within 1e-4.
    assert update.duration <= (first.duration - t_switch) * (1 + 1e-4)
    before = first.at(np.arange(round(t_switch / dt)) * dt)
    after = update.at(np.arange(0.0, update.duration, dt))
    t = np.concatenate((before.t, t_switch + after.t))
    v = np.concatenate((before.v, after.v))
    s = np.concatenate((before.s, after.s))
    keep = np.concatenate(([True], np.diff(t) > 1e-12))
    t, v, s = t[keep], v[keep], s[keep]
    assert np.all(np.diff(s) >= -1e-12)  # position continuous and monotone at the switch
    i = np.searchsorted(t, t_switch)
    assert abs(v[i] - v[i - 1]) <= LGV.a_max * 2 * dt
    a = np.diff(v) / np.diff(t)
    jerk = np.diff(a) / np.diff(t)[1:]
    assert np.abs(jerk).max() <= LGV.j_max * (1 + PROMISED["jerk"]) + 1e-6


def test_an_order_update_from_any_state_of_the_previous_plan_is_planned():
    # States read off our own plan lie on the boundary of what j_max reaches, some a
    # rounding outside it (they were refused, and a refusal inside plan_route surfaced as a
    # KeyError). They are planned without a warning (a controller replanning at 10 Hz
    # would see one per cycle), and the result stays within the promise.
    route = Route.from_vda5050(three_edge_order())
    first = plan_route(route, LGV)
    rounded = 0
    for t in np.linspace(0.05, first.duration - 0.05, 41):
        state = first.at([t])
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            update = plan_route(route, LGV, start_s=float(state.s[0]), v0=float(state.v[0]),
                                a0=float(state.a[0]))
        assert not caught, (t, [str(w.message) for w in caught])
        rounded += any(a.name.endswith("state_rounding") and a.outcome == "answered"
                       for a in update.legs[0].attempts)
        assert update.verification.ok, (t, update.verification.summary())
        traj = update.at(np.arange(0.0, update.duration, 1e-3))  # uniform: plain differences
        j_fd = np.diff(traj.v, 2) / 1e-6
        assert np.abs(j_fd).max() <= LGV.j_max * (1 + PROMISED["jerk"]) + 1e-6, t
        # Never much faster than continuing the old plan.
        assert t + update.duration >= first.duration * (1 - 1e-3), t
    assert rounded > 0  # the case is exercised: states a rounding outside j_max's reach


def test_legs_planned_on_an_executor_give_the_same_profile():
    route = Route.from_vda5050(three_edge_order())
    with ThreadPoolExecutor(2) as ex:
        parallel = plan_route(route, LGV, executor=ex)
    serial = plan_route(route, LGV)
    assert parallel.duration == serial.duration
    np.testing.assert_array_equal(parallel.node_times, serial.node_times)


def test_bad_arguments_name_themselves():
    route = Route.from_vda5050(three_edge_order())
    with pytest.raises(InvalidInputError, match="`start_s`"):
        plan_route(route, LGV, start_s=route.length + 1.0)
    with pytest.raises(InvalidInputError, match="plan_route sets 'vf'"):
        plan_route(route, LGV, vf=1.0)
    with pytest.raises(InvalidInputError, match=r"`route` must be a speedplan\.route\.Route"):
        plan_route("order.json", LGV)


def test_route_jobs_are_validated_plan_jobs_whose_plans_are_the_routes_legs():
    from speedplan import plan, plan_many
    from speedplan.batch import PlanJob
    from speedplan.model import PlanRequest
    from speedplan.route_plan import route_jobs

    route = Route.from_vda5050(three_edge_order())
    jobs, starts = route_jobs(route, LGV, refine="auto", time_limit=60.0)
    assert all(isinstance(j, PlanJob) and isinstance(j.request, PlanRequest) for j in jobs)
    assert [j.time_limit for j in jobs] == [60.0] * len(jobs)
    assert starts == [0.0, pytest.approx(10.0)]
    assert sum(j.request.path.length for j in jobs) == pytest.approx(route.length, rel=1e-12)
    assert jobs[1].request.spans[0].v_max == ARC_LIMIT  # the arc edge's limit, leg-local
    profile = plan_route(route, LGV)
    with ThreadPoolExecutor(2) as ex:
        batch = plan_many(jobs, ex)
        parallel = plan_route(route, LGV, executor=ex)
    by_hand = [plan(j.request.path, LGV, spans=j.request.spans) for j in jobs]
    for leg, result, other, own in zip(profile.legs, batch, parallel.legs, by_hand, strict=True):
        assert result.profile is not None
        assert leg.duration == result.profile.duration == other.duration == own.duration


def test_route_jobs_refuse_an_invalid_option_naming_the_leg():
    from speedplan.route_plan import route_jobs

    route = Route.from_vda5050(three_edge_order())
    with pytest.raises(InvalidInputError, match=r"on the leg from s=0 m to s=10 m of the route: "
                                                r"`refine` must be one of 'auto', 'always'"):
        route_jobs(route, LGV, refine="sometimes")  # type: ignore[typeddict-item]
    with pytest.raises(InvalidInputError, match=r"on the leg from s=0 m .*`time_limit`"):
        route_jobs(route, LGV, time_limit=-1.0)
    with pytest.raises(InvalidInputError, match="plan_route sets 'v_limit' from the route"):
        route_jobs(route, LGV, v_limit=([0.0], [1.0]))  # type: ignore[call-arg]

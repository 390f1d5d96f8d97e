"""Order updates: plan_route_update() continues the motion being driven.

Oracles: the old plan's own sampled state at the switch (position, speed, acceleration,
heading must be taken over unchanged), finite differences of the stitched trajectory, and
the orders' geometry.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from shared import LGV

from speedplan import InvalidInputError, Route, plan_route, plan_route_update


def _node(i, x, y, released=True, deviation=0.0):
    return {"nodeId": f"n{i}", "sequenceId": 2 * i, "released": released, "actions": [],
            "nodePosition": {"x": x, "y": y, "mapId": "hall", "allowedDeviationXY": deviation}}


def _edge(i, released=True, **fields):
    return {"edgeId": f"e{i}", "sequenceId": 2 * i + 1, "released": released, "actions": [],
            "startNodeId": f"n{i}", "endNodeId": f"n{i + 1}", **fields}


def _order(update, nodes, edges, order_id="o"):
    return Route.from_vda5050({
        "headerId": update, "timestamp": "2024-05-06T08:00:00.00Z", "version": "2.0.0",
        "manufacturer": "ExampleAGV", "serialNumber": "LGV-0042", "orderId": order_id,
        "orderUpdateId": update, "nodes": nodes, "edges": edges})


def base_with_horizon():
    """Base n0 (0,0) - n1 (10,0); horizon n1 - n2 (20,0) - n3 (20,10)."""
    return _order(0, [_node(0, 0, 0), _node(1, 10, 0), _node(2, 20, 0, False, 0.5),
                      _node(3, 20, 10, False)],
                  [_edge(0), _edge(1, False), _edge(2, False)])


def horizon_released():
    return _order(1, [_node(1, 10, 0), _node(2, 20, 0, deviation=0.5), _node(3, 20, 10)],
                  [_edge(1), _edge(2)])


def assert_continues(old, new, t, dt=0.01):
    """At the switch the new motion starts in the old one's state; stitched, it stays
    within the limits (finite differences of the sampled speed)."""
    before, after = old.at(t), new.at(0.0)
    for name in ("x", "y", "v", "a"):
        assert getattr(after, name)[0] == pytest.approx(getattr(before, name)[0], abs=1e-6), name
    assert math.remainder(after.heading[0] - before.heading[0], 2 * math.pi) == pytest.approx(
        0.0, abs=1e-9)
    head = old.at(np.arange(0.0, t, dt))
    tail = new.sample(dt)
    times = np.concatenate((head.t, t + tail.t))
    v = np.concatenate((head.v, tail.v))
    step = np.diff(times)
    keep = step > 1e-9
    acc = np.diff(v)[keep] / step[keep]
    assert acc.max() <= LGV.a_max * 1.01 and -acc.min() <= LGV.a_decel * 1.01
    xy = np.column_stack((np.concatenate((head.x, tail.x)), np.concatenate((head.y, tail.y))))
    jump = np.hypot(*np.diff(xy, axis=0).T)
    assert jump.max() <= LGV.v_max * dt * 1.01  # no jump in position at the switch
    return tail


def test_a_released_horizon_is_driven_through_without_the_old_stop():
    old = plan_route(base_with_horizon(), LGV)
    new = plan_route_update(old, horizon_released(), 3.0)
    tail = assert_continues(old, new, 3.0)
    assert new.route.order_update_id == 1 and new.route.length > 29.0
    at_n1 = np.argmin(np.abs(tail.x - 10.0) + np.abs(tail.y))
    assert tail.v[at_n1] > 1.0  # n1 was the end of the base, now the vehicle drives on
    assert new.node_times[0] != new.node_times[0]  # n0 is behind the vehicle: NaN
    assert new.node_times[1] + 3.0 < old.node_times[1]
    assert new.verify().ok


def test_a_reversal_released_by_an_update_continues_from_the_vehicle_state():
    old = plan_route(base_with_horizon(), LGV)
    back = _order(1, [_node(1, 10, 0), _node(2, 4, 0)], [_edge(1, orientation=math.pi)])
    new = plan_route_update(old, back, 4.0)
    tail = assert_continues(old, new, 4.0)
    assert tail.direction[-1] == -1 and tail.x[-1] == pytest.approx(4.0, abs=1e-6)
    assert new.turns == ()  # the vehicle backs out facing as it came: no turn
    assert np.max(np.abs(np.diff(tail.heading))) < 1e-9


def test_an_update_at_the_node_the_vehicle_waits_on_turns_it_there():
    old = plan_route(base_with_horizon(), LGV)
    up = _order(1, [_node(1, 10, 0), _node(2, 10, 10)], [_edge(1, maxRotationSpeed=0.4)])
    new = plan_route_update(old, up, old.duration)
    assert_continues(old, new, old.duration)
    (turn,) = new.turns
    assert turn.node == 1 and turn.turn.angle == pytest.approx(math.pi / 2)
    assert new.node_times[1] == 0.0 and new.node_leave_times[1] == pytest.approx(turn.duration)


def test_too_late_to_cut_the_joining_corner_the_vehicle_stops_and_turns():
    old = plan_route(_order(0, [_node(0, 0, 0), _node(1, 10, 0, deviation=1.0),
                                _node(2, 10, 10, False)], [_edge(0), _edge(1, False)]), LGV)
    up = _order(1, [_node(1, 10, 0, deviation=1.0), _node(2, 10, 10)], [_edge(1)])
    early = plan_route_update(old, up, 2.0)
    assert early.route.rounded_nodes == (1,) and early.turns == ()
    t_late = float(old.node_times[1]) - 0.5  # 2 cm before n1: inside the corner's start
    late = plan_route_update(old, up, t_late)
    assert late.route.rounded_nodes == () and [t.node for t in late.turns] == [1]
    assert_continues(old, late, t_late)


def test_updates_that_do_not_continue_the_order_are_refused():
    old = plan_route(base_with_horizon(), LGV)
    with pytest.raises(InvalidInputError, match="orderId"):
        plan_route_update(old, _order(1, [_node(1, 10, 0), _node(2, 20, 0)], [_edge(1)],
                                      order_id="other"), 1.0)
    with pytest.raises(InvalidInputError, match="order_update_id"):
        plan_route_update(old, _order(0, [_node(1, 10, 0), _node(2, 20, 0)], [_edge(1)]), 1.0)
    stray = _order(1, [{**_node(1, 10, 0), "nodeId": "x"}, _node(2, 20, 0)],
                   [{**_edge(1), "startNodeId": "x"}])
    with pytest.raises(InvalidInputError, match="not a node of the current base"):
        plan_route_update(old, stray, 1.0)


def test_an_update_during_a_turn_on_the_spot_is_refused_by_time():
    old = plan_route(_order(0, [_node(0, 0, 0), _node(1, 10, 0), _node(2, 10, 10)],
                            [_edge(0), _edge(1)]), LGV)
    (turn,) = old.turns
    middle = float(old.turn_times[0]) + 0.5 * turn.duration
    up = _order(1, [_node(1, 10, 0), _node(2, 10, 10)], [_edge(1)])
    with pytest.raises(InvalidInputError, match="turning on the spot"):
        plan_route_update(old, up, middle)


def test_updates_of_a_straight_order_replan_to_the_same_arrival():
    # Both edges at 1.5 m/s: from anywhere on the first, the rest of the base is one straight
    # stretch at one speed limit, planned in closed form. The edges' limits are summed from
    # the switch: where that ended an ulp before the rest of the path (one of these), its
    # last point kept v_max, and the update went to a grid, 6.9e-7 from the original arrival.
    nodes = [_node(0, 0, 0), _node(1, 10, 0), _node(2, 40, 0)]
    edges = [_edge(0, maxSpeed=1.5), _edge(1, maxSpeed=1.5)]
    old = plan_route(_order(0, nodes, edges), LGV)
    for t in np.linspace(0.1, old.duration - 0.1, 60):
        new = plan_route_update(old, _order(1, nodes, edges), float(t))
        assert t + new.duration == pytest.approx(old.duration, rel=1e-9)
        answered = {a.name for a in new.legs[0].attempts if a.outcome == "answered"}
        assert answered <= {"model", "closed_form", "forced_motion"}  # no grid

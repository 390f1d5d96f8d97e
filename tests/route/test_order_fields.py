"""VDA 5050 order fields: corners within the node's deviation (2.x radius, 3.0 ellipse) and the
edges' corridors, the rotation fields, and one warning per order for every field the planner
does not honour as written.

Oracles: distances of the sampled path to the nodes and to the edges' lines (shapely), and
the order's own numbers.
"""

from __future__ import annotations

import copy
import math
import warnings
from pathlib import Path as FsPath

import numpy as np
import pytest
import shapely
import shapely.affinity
from shared import LGV

from speedplan import Route, plan_route
from speedplan.route.vda5050 import OrderWarning

ORDERS = FsPath(__file__).resolve().parents[2] / "paths" / "orders"


def _node(i, x, y, version="2.1.0", deviation=None, **pos):
    position = {"x": x, "y": y, "mapId": "hall", **pos}
    if deviation is not None:
        position["allowedDeviationXY"] = deviation
    return {"nodeId": f"n{i}", "sequenceId": 2 * i, "released": True,
            "nodePosition": position, "actions": []}


def _edge(i, version="2.1.0", **fields):
    e = {"edgeId": f"e{i}", "sequenceId": 2 * i + 1, "released": True, "actions": [], **fields}
    if version.startswith("2"):
        e |= {"startNodeId": f"n{i}", "endNodeId": f"n{i + 1}"}
    return e


def _order(nodes, edges, version="2.1.0"):
    return {"headerId": 0, "timestamp": "2024-05-06T08:00:00.00Z", "version": version,
            "manufacturer": "ExampleAGV", "serialNumber": "LGV-0042", "orderId": "o",
            "orderUpdateId": 0, "nodes": nodes, "edges": edges}


def corner(version="2.1.0", deviation=1.0, first=None, second=None, theta=None):
    """n0 (0,0) -> n1 (10,0) -> n2 (10,10): a left turn of 90° at n1."""
    extra = {} if theta is None else {"theta": theta}
    nodes = [_node(0, 0, 0, version), _node(1, 10, 0, version, deviation, **extra),
             _node(2, 10, 10, version)]
    return _order(nodes, [_edge(0, version, **(first or {})), _edge(1, version, **(second or {}))],
                  version)


def _read(doc):
    with warnings.catch_warnings():
        warnings.simplefilter("error", OrderWarning)  # these orders need no note
        return Route.from_vda5050(doc)


def _sampled_path(route, step=0.002):
    s = np.linspace(0.0, route.length, int(route.length / step) + 1)
    return s, np.asarray(route.path.point(s))


def test_a_corner_stays_inside_the_node_radius():
    route = _read(corner(deviation=1.0))
    assert route.rounded_nodes == (1,)
    _, xy = _sampled_path(route)
    gap = float(np.min(np.hypot(xy[:, 0] - 10.0, xy[:, 1])))
    assert gap <= 1.0 + 1e-6
    assert gap > 0.9  # the corner uses what it is given: it is no square corner


@pytest.mark.parametrize("width", [0.05, 0.2, 0.5])
def test_a_corner_stays_inside_both_edges_corridors(width):
    """Left turn: the corner cuts into both edges' left sides, which the corridors bound."""
    wide = {"corridor": {"leftWidth": width, "rightWidth": 0.0,
                         "corridorRefPoint": "KINEMATICCENTER"}}
    route = _read(corner(deviation=1.0, first=wide, second=wide))
    s, xy = _sampled_path(route)
    points = shapely.points(xy)
    on_first, on_second = s <= route.node_s[1], s >= route.node_s[1]
    to_first = shapely.distance(points[on_first], shapely.LineString([(0, 0), (10, 0)]))
    to_second = shapely.distance(points[on_second], shapely.LineString([(10, 0), (10, 10)]))
    assert max(to_first.max(), to_second.max()) <= width * (1 + 1e-6)
    assert max(to_first.max(), to_second.max()) >= 0.99 * width  # and uses it
    gap = float(np.min(np.hypot(xy[:, 0] - 10.0, xy[:, 1])))
    assert gap == pytest.approx(width * math.sqrt(2.0), rel=1e-3)  # d cos 45° = width


def test_a_corridor_without_room_on_the_inner_side_makes_the_vehicle_stop_and_turn():
    right_only = {"corridor": {"leftWidth": 0.0, "rightWidth": 2.0}}
    route = _read(corner(deviation=1.0, first=right_only))
    assert route.rounded_nodes == () and route.stop_s.tolist() == [0.0, 10.0, 20.0]
    assert len(plan_route(route, LGV).turns) == 1


@pytest.mark.parametrize("angle", [0.0, 0.7, -1.2])
def test_a_corner_stays_inside_the_3_0_deviation_ellipse(angle):
    """The corner passes through the ellipse, as deep as the ellipse reaches along the
    corner's bisector (found with shapely: the ellipse as a polygon, cut by the bisector)."""
    a, b = 1.0, 0.2
    route = _read(corner("3.0.0", deviation={"a": a, "b": b, "theta": angle}))
    ellipse = shapely.affinity.rotate(shapely.affinity.scale(
        shapely.Point(10.0, 0.0).buffer(1.0, quad_segs=2048), a, b), angle, use_radians=True)
    _, xy = _sampled_path(route)
    assert np.any(shapely.contains_xy(ellipse.buffer(1e-6), xy[:, 0], xy[:, 1]))
    middle = np.asarray(route.path.point(route.node_s[1])).reshape(2)
    bisector = shapely.LineString([(10.0, 0.0), (10.0 - 5.0, 5.0)])
    reach = shapely.intersection(ellipse.exterior, bisector)
    depth = shapely.distance(shapely.Point(10.0, 0.0), reach)
    assert math.hypot(middle[0] - 10.0, middle[1]) == pytest.approx(depth, rel=1e-4)
    gap = float(np.min(np.hypot(xy[:, 0] - 10.0, xy[:, 1])))
    assert gap >= b * (1 - 1e-6)  # never tighter than the circle inside the ellipse


@pytest.mark.parametrize(("version", "first", "second"), [
    ("2.1.0", {"rotationAllowed": False}, None),
    ("2.1.0", None, {"rotationAllowed": False}),
    ("3.0.0", None, {"reachOrientationBeforeEntering": True}),
])
def test_rotation_fields_keep_the_vehicle_from_turning_on_the_edge(version, first, second):
    route = _read(corner(version, deviation=({"a": 1.0, "b": 1.0, "theta": 0.0}
                                             if version.startswith("3") else 1.0),
                         first=first, second=second))
    assert route.rounded_nodes == ()
    profile = plan_route(route, LGV)
    assert [t.node for t in profile.turns] == [1]
    assert profile.node_leave_times[1] > profile.node_times[1]


@pytest.mark.parametrize(("theta", "rounded"), [(math.pi / 4, True), (0.0, False)])
def test_a_node_theta_rounds_the_corner_only_if_the_corner_meets_it(theta, rounded):
    route = _read(corner(deviation=1.0, theta=theta))
    assert (route.rounded_nodes == (1,)) is rounded
    if rounded:
        heading = float(route.path.heading(route.node_s[1]))
        assert heading == pytest.approx(theta, abs=1e-3)
    else:
        # The vehicle stops on n1; arriving at theta 0, it turns once, to the next edge.
        angles = [t.turn.angle for t in plan_route(route, LGV).turns]
        assert angles == pytest.approx([math.pi / 2])


def test_a_global_orientation_against_a_straight_edge_drives_it_backwards():
    doc = corner(deviation=0.0, second={"orientation": -math.pi / 2,
                                        "orientationType": "GLOBAL"})
    route = _read(doc)
    assert route.edges[1].reverse and not route.edges[0].reverse
    traj = plan_route(route, LGV).sample(0.05)
    assert traj.direction[-1] == -1
    # The vehicle faces -y while it drives the edge to +y: it turned by -90° on n1.
    assert math.remainder(traj.heading[-1] + math.pi / 2, 2 * math.pi) == pytest.approx(0.0,
                                                                                         abs=1e-9)


def _notes(doc):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        route = Route.from_vda5050(doc)
    ours = [w for w in caught if issubclass(w.category, OrderWarning)]
    assert len(ours) == (1 if route.notes else 0)  # one warning per order
    if ours:
        for note in route.notes:
            assert note in str(ours[0].message)
    return route


@pytest.mark.parametrize(("version", "where", "fields", "words"), [
    ("2.0.0", "edges", {"direction": "backward"}, ("edges[0].direction", "orientation")),
    ("2.0.0", "edges", {"maxHeight": 2.0}, ("edges[0].maxHeight", "height")),
    ("3.0.0", "edges", {"maximumMobileRobotHeight": 2.0},
     ("edges[0].maximumMobileRobotHeight", "height")),
    ("2.0.0", "edges", {"orientation": math.pi / 2}, ("edges[0].orientation", "crab")),
    ("2.0.0", "edges", {"maxspeed": 0.5}, ("edges[0].maxspeed", "not a field")),
    ("3.0.0", "edges", {"corridor": {"leftWidth": 1.0, "rightWidth": 1.0,
                                     "corridorRefPoint": "CONTOUR"}},
     ("edges[0].corridor.corridorRefPoint", "contour")),
])
def test_fields_not_honoured_are_named_with_their_edge_and_why(version, where, fields, words):
    doc = corner(version, deviation=None)
    doc[where][0] |= fields
    route = _notes(doc)
    assert len(route.notes) == 1
    for word in words:
        assert word.lower() in route.notes[0].lower()
    assert not route.edges[0].reverse  # "direction" does not reverse


def test_the_notes_of_an_order_come_in_one_warning():
    doc = corner("2.0.0", deviation=None)
    doc["edges"][0]["direction"] = "backward"
    doc["edges"][1]["maxHeight"] = 2.0
    del doc["nodes"][1]["actions"]
    del doc["headerId"]
    route = _notes(doc)
    assert len(route.notes) == 4
    assert any("nodes[1].actions" in n and "missing" in n for n in route.notes)
    assert any("headerId" in n for n in route.notes)


def test_rotation_not_allowed_on_a_curved_edge_is_noted():
    arc = {"degree": 2, "knotVector": [0, 0, 0, 1, 1, 1],
           "controlPoints": [{"x": 10.0, "y": 0.0, "weight": 1.0},
                             {"x": 15.0, "y": 0.0, "weight": math.sqrt(0.5)},
                             {"x": 15.0, "y": 5.0, "weight": 1.0}]}
    nodes = [_node(0, 0, 0), _node(1, 10, 0), _node(2, 15, 5)]
    doc = _order(nodes, [_edge(0), _edge(1, trajectory=arc, rotationAllowed=False)])
    route = _notes(doc)
    assert len(route.notes) == 1 and "edges[1].rotationAllowed" in route.notes[0]


@pytest.mark.parametrize("name", ["order_v2.json", "order_v3.json"])
def test_sample_orders_are_spelled_as_the_schemas_and_need_no_note(name):
    route = _read(ORDERS / name)
    assert route.notes == ()
    text = (ORDERS / name).read_text()
    assert "allowedDeviationXy" not in text


def test_an_order_without_notes_does_not_warn():
    _read(copy.deepcopy(corner()))

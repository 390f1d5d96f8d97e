"""VDA 5050 orders (2.0, 2.1, 3.0) read as routes: geometry, limits, stops, validation.

Oracles: node positions and hypot for straight edges, scipy ``BSpline`` + ``quad`` for NURBS
edges, shapely for lengths; never the reader under test.
"""

from __future__ import annotations

import copy
import json
import math
import re
from pathlib import Path as FsPath

import numpy as np
import pytest
import shapely
from scipy.integrate import quad
from scipy.interpolate import BSpline

from speedplan import InvalidInputError
from speedplan.route import Route

ORDERS = FsPath(__file__).resolve().parents[2] / "paths" / "orders"


def node(i, x, y, actions=(), **pos):
    return {"nodeId": f"N{i}", "sequenceId": 2 * i, "released": True,
            "nodePosition": {"x": x, "y": y, "mapId": "hall", **pos}, "actions": list(actions)}


def edge(i, version="2.0.0", **fields):
    e = {"edgeId": f"E{i}", "sequenceId": 2 * i + 1, "released": True, "actions": []}
    if version.startswith("2"):
        e |= {"startNodeId": f"N{i}", "endNodeId": f"N{i + 1}"}
    return e | fields


def straight_order(version="2.0.0"):
    """Two straight edges, 10 m in all, along the x axis (N0 - N1 - N2)."""
    return {"headerId": 0, "timestamp": "2024-01-01T00:00:00.00Z", "version": version,
            "manufacturer": "m", "serialNumber": "s", "orderId": "o", "orderUpdateId": 0,
            "nodes": [node(0, 0.0, 0.0), node(1, 5.0, 0.0), node(2, 10.0, 0.0)],
            "edges": [edge(0, version), edge(1, version)]}


LINE_TRAJ = {"degree": 1, "knotVector": [0, 0, 1, 1],
             "controlPoints": [{"x": 0.0, "y": 0.0}, {"x": 5.0, "y": 0.0}]}
HARD = {"actionType": "pick", "actionId": "a1", "blockingType": "HARD"}


def with_(doc, path, value):
    """A deep copy of ``doc`` with the item at ``path`` (a tuple of keys) set (or deleted)."""
    out = copy.deepcopy(doc)
    target = out
    for key in path[:-1]:
        target = target[key]
    if value is KeyError:
        del target[path[-1]]
    else:
        target[path[-1]] = value
    return out


# ---- the sample orders ---------------------------------------------------------------------------
def _rational_point(k, t, ctrl, w, x):
    """Independent rational B-spline point (scipy BSpline on homogeneous coordinates)."""
    hom = BSpline(t, np.column_stack((ctrl * w[:, None], w)), k)(x)
    return hom[:2] / hom[2]


def test_v2_and_v3_forms_of_the_sample_route_give_equal_geometry():
    r2 = Route.from_vda5050(ORDERS / "order_v2.json")
    r3 = Route.from_vda5050(ORDERS / "order_v3.json")
    assert (r2.version, r3.version) == ("2.0.0", "3.0.0")
    for r in (r2, r3):
        assert r.length == pytest.approx(sum(e.path.length for e in r.edges), rel=1e-15)
        assert [e.v_max for e in r.edges] == [1.0, 1.5]
        assert [e.yaw_rate_max for e in r.edges] == [0.5, None]
        assert [n.stop for n in r.nodes] == [False, True, True]  # HARD pick and drop
        assert [n.allowed_deviation_xy for n in r.nodes] == [0.05] * 3
        assert r.stop_reasons[1].startswith("node 'N1'")
    assert r2.length == r3.length
    np.testing.assert_array_equal(r2.node_s, r3.node_s)
    np.testing.assert_array_equal(r2.stop_s, r3.stop_s)
    s = np.linspace(0.0, r2.length, 400)
    for e2, e3, (a, b) in zip(r2.edges, r3.edges, r2.edge_spans, strict=True):
        u = s[(s >= a) & (s <= b)] - a
        np.testing.assert_allclose(e2.path.point(u), e3.path.point(u), rtol=0, atol=1e-9)
        np.testing.assert_allclose(e2.path.heading(u), e3.path.heading(u), rtol=0, atol=1e-9)


def test_sample_route_geometry_against_scipy_and_shapely():
    doc = json.loads((ORDERS / "order_v2.json").read_text())
    route = Route.from_vda5050(doc)
    traj = doc["edges"][0]["trajectory"]
    k, t = traj["degree"], np.array(traj["knotVector"], float)
    ctrl = np.array([[p["x"], p["y"]] for p in traj["controlPoints"]])
    w = np.array([p["weight"] for p in traj["controlPoints"]])

    def speed(x, h=1e-7):
        lo, hi = max(x - h, 0.0), min(x + h, 1.0)
        return np.linalg.norm(_rational_point(k, t, ctrl, w, hi)
                              - _rational_point(k, t, ctrl, w, lo)) / (hi - lo)

    def arc(x):
        pts = [b for b in (0.4, 0.7) if b < x]
        return quad(speed, 0.0, x, points=pts or None, epsabs=1e-11, epsrel=1e-11, limit=200)[0]

    bend = route.edges[0].path
    assert bend.length == pytest.approx(arc(1.0), abs=1e-6)
    for x in (0.1, 0.35, 0.55, 0.9):  # the point at the independent arc length of parameter x
        np.testing.assert_allclose(bend.point(arc(x)), _rational_point(k, t, ctrl, w, x),
                                   atol=1e-6)
    tau = np.linspace(0, 1, 20001)
    dense = shapely.LineString([_rational_point(k, t, ctrl, w, x) for x in tau])
    assert bend.length == pytest.approx(dense.length, rel=1e-6)
    # The straight edge: between the node positions (9, 8) and (9, 20).
    straight = route.edges[1].path
    line = shapely.LineString([(9, 8), (9, 20)])
    assert straight.length == pytest.approx(line.length, rel=1e-15)
    for u in (0.0, 3.3, 12.0):
        np.testing.assert_allclose(straight.point(u), np.asarray(line.interpolate(u).coords)[0],
                                   atol=1e-12)
    assert route.length == pytest.approx(dense.length + line.length, rel=1e-6)
    np.testing.assert_allclose(route.node_s, [0.0, bend.length, bend.length + 12.0], rtol=1e-15)


# ---- what users found ----------------------------------------------------------------------------
def test_every_edge_is_read_not_only_the_first_with_a_trajectory():
    doc = with_(straight_order(), ("edges", 0, "trajectory"), LINE_TRAJ)
    route = Route.from_vda5050(doc)
    assert route.length == pytest.approx(10.0, rel=1e-15)  # was 5 m: only edge 0 was read
    assert route.edge_spans == ((0.0, 5.0), (5.0, 10.0))
    np.testing.assert_allclose(route.edges[1].path.point([0.0, 5.0]), [[5, 0], [10, 0]],
                               atol=1e-12)


@pytest.mark.parametrize(("version", "key"), [("2.0.0", "maxSpeed"), ("2.1.0", "maxSpeed"),
                                              ("3.0.0", "maximumSpeed")])
def test_edge_speed_limits_are_read_with_each_versions_name(version, key):
    doc = with_(straight_order(version), ("edges", 0, key), 1.2)
    route = Route.from_vda5050(doc)
    assert [e.v_max for e in route.edges] == [1.2, None]


@pytest.mark.parametrize(("version", "key", "right"), [("2.0.0", "maximumSpeed", "maxSpeed"),
                                                       ("3.0.0", "maxSpeed", "maximumSpeed")])
def test_the_other_versions_speed_name_is_refused_not_ignored(version, key, right):
    doc = with_(straight_order(version), ("edges", 1, key), 1.2)
    with pytest.raises(InvalidInputError, match=rf"`edges\[1\]\.{key}`.*`{right}`"):
        Route.from_vda5050(doc)


def test_v3_controlpoints_only_trajectory_uses_degree_1_and_uniform_clamped_knots():
    doc = with_(straight_order("3.0.0"), ("edges", 0, "trajectory"),
                {"controlPoints": [{"x": 0, "y": 0}, {"x": 5, "y": 0}]})
    assert Route.from_vda5050(doc).length == pytest.approx(10.0, rel=1e-15)
    # A cubic with `degree` only: the same curve as 2.0's explicit uniform clamped knots.
    pts = [{"x": 0, "y": 0}, {"x": 2, "y": 1}, {"x": 3, "y": -1}, {"x": 4, "y": 0.5},
           {"x": 5, "y": 0}]
    v3 = with_(straight_order("3.0.0"), ("edges", 0, "trajectory"),
               {"degree": 3, "controlPoints": pts})
    v2 = with_(straight_order("2.0.0"), ("edges", 0, "trajectory"),
               {"degree": 3, "knotVector": [0, 0, 0, 0, 0.5, 1, 1, 1, 1], "controlPoints": pts})
    p3, p2 = (Route.from_vda5050(d).edges[0].path for d in (v3, v2))
    assert p3.length == p2.length
    s = np.linspace(0, p2.length, 50)
    np.testing.assert_array_equal(p3.point(s), p2.point(s))
    ctrl = np.array([[p["x"], p["y"]] for p in pts], float)
    spline = BSpline(np.array([0, 0, 0, 0, 0.5, 1, 1, 1, 1.0]), ctrl, 3)
    np.testing.assert_allclose(p3.point(0.0), spline(0.0), atol=1e-14)
    np.testing.assert_allclose(p3.point(p3.length), spline(1.0), atol=1e-12)


def test_v2_trajectory_needs_degree_and_knot_vector():
    for key in ("degree", "knotVector"):
        traj = {k: v for k, v in LINE_TRAJ.items() if k != key}
        doc = with_(straight_order("2.0.0"), ("edges", 0, "trajectory"), traj)
        with pytest.raises(InvalidInputError,
                           match=rf"`edges\[0\]\.trajectory`: `{key}` is missing.*2\.0"):
            Route.from_vda5050(doc)


def test_nurbs_position_jump_and_unclamped_knots_in_an_edge_are_refused():
    jump = {"degree": 1, "knotVector": [0, 0, 0.5, 0.5, 1, 1],
            "controlPoints": [{"x": 0, "y": 0}, {"x": 1, "y": 0}, {"x": 4, "y": 0},
                              {"x": 5, "y": 0}]}
    doc = with_(straight_order(), ("edges", 0, "trajectory"), jump)
    with pytest.raises(InvalidInputError, match=re.escape(
            "`edges[0].trajectory`: `knots`: knot 0.5 is repeated 2 times")):
        Route.from_vda5050(doc)
    unclamped = {"degree": 2, "knotVector": [0, 0.2, 0.4, 0.6, 0.8, 1.0],
                 "controlPoints": [{"x": 0, "y": 0}, {"x": 2, "y": 1}, {"x": 5, "y": 0}]}
    doc = with_(straight_order(), ("edges", 0, "trajectory"), unclamped)
    with pytest.raises(InvalidInputError,
                       match=re.escape("`edges[0].trajectory`: `knots` are not clamped")):
        Route.from_vda5050(doc)


def test_node_positions_give_straight_edges_and_stops_where_the_heading_changes():
    doc = with_(straight_order(), ("nodes", 2, "nodePosition", "y"), 5.0)  # turn left at N1
    route = Route.from_vda5050(doc)
    assert route.length == pytest.approx(5.0 + math.hypot(5.0, 5.0), rel=1e-15)
    assert route.stop_s.tolist() == [0.0, 5.0, route.length]
    assert "heading changes by 0.785 rad" in route.stop_reasons[1]
    assert [len(leg) for leg in route.legs()] == [1, 1]
    straight = Route.from_vda5050(straight_order())  # collinear: no stop at N1
    assert straight.stop_s.tolist() == [0.0, 10.0]
    assert [[e.edge_id for e in leg] for leg in straight.legs()] == [["E0", "E1"]]


@pytest.mark.parametrize(("actions", "version", "stops"), [
    ([HARD], "2.0.0", True), ([HARD | {"blockingType": "SOFT"}], "2.1.0", True),
    ([HARD | {"blockingType": "NONE"}], "2.0.0", False),
    ([HARD | {"blockingType": "SINGLE"}], "3.0.0", False),  # 3.0: allows driving
    ([HARD | {"blockingType": "NONE"}, HARD | {"actionId": "a2"}], "3.0.0", True),
])
def test_blocking_node_actions_stop_the_vehicle(actions, version, stops):
    route = Route.from_vda5050(with_(straight_order(version), ("nodes", 1, "actions"), actions))
    assert route.nodes[1].stop is stops
    assert route.stop_s.tolist() == ([0.0, 5.0, 10.0] if stops else [0.0, 10.0])


def test_blocking_edge_action_stops_at_the_edges_start_node():
    route = Route.from_vda5050(with_(straight_order(), ("edges", 1, "actions"), [HARD]))
    assert route.edges[1].stop and not route.nodes[1].stop
    assert route.stop_s.tolist() == [0.0, 5.0, 10.0]
    assert "edge 'E1'" in route.stop_reasons[1]


@pytest.mark.parametrize(("fields", "reverse"), [
    ({}, False), ({"orientation": 0.0}, False), ({"orientation": math.pi / 2}, False),
    ({"orientation": math.pi}, True), ({"orientation": -2.0}, True),
    ({"orientation": math.pi, "orientationType": "TANGENTIAL"}, True),
    # GLOBAL: the map heading; on this edge along +x, π faces against the travel direction.
    ({"orientation": math.pi, "orientationType": "GLOBAL"}, True),
    ({"orientation": 0.0, "orientationType": "GLOBAL"}, False),
])
def test_edge_orientation_gives_the_driving_direction(fields, reverse):
    doc = straight_order()
    doc["edges"][1] |= fields
    route = Route.from_vda5050(doc)
    assert route.edges[1].reverse is reverse
    assert route.edges[1].path.heading(0.0) == pytest.approx(0.0, abs=1e-15)  # travel order
    # A change of driving direction between edges is a stop (a cusp), even on a straight.
    assert route.stop_s.tolist() == ([0.0, 5.0, 10.0] if reverse else [0.0, 10.0])
    if reverse:
        assert "driving direction changes" in route.stop_reasons[1]


def test_only_the_released_base_is_planned():
    doc = straight_order()
    doc["nodes"].append(node(3, 15.0, 0.0))
    doc["edges"].append(edge(2))
    doc["nodes"][3]["released"] = doc["nodes"][2]["released"] = False
    doc["edges"][2]["released"] = doc["edges"][1]["released"] = False
    route = Route.from_vda5050(doc)
    assert len(route.edges) == 3 and len(route.base_edges) == 1
    assert route.length == 5.0 and route.node_s.tolist() == [0.0, 5.0]
    assert route.stop_s.tolist() == [0.0, 5.0]  # the vehicle must be able to stop at N1
    assert route.stop_reasons[-1] == "end of the released base"


def test_a_node_without_position_between_two_trajectories_is_fine():
    doc = with_(straight_order(), ("edges", 0, "trajectory"), LINE_TRAJ)
    doc["edges"][1]["trajectory"] = {"degree": 1, "knotVector": [0, 0, 1, 1],
                                     "controlPoints": [{"x": 5.0, "y": 0.0},
                                                       {"x": 10.0, "y": 0.0}]}
    del doc["nodes"][1]["nodePosition"]
    route = Route.from_vda5050(doc)
    assert route.nodes[1].position is None and route.length == pytest.approx(10.0, rel=1e-15)
    # ...but the two trajectories must still meet there.
    doc["edges"][1]["trajectory"]["controlPoints"][0]["y"] = 0.5
    with pytest.raises(InvalidInputError, match=r"`edges\[1\]\.path` starts.*end of `edges\[0\]"):
        Route.from_vda5050(doc)


def test_allowed_deviation_sets_how_far_a_trajectory_may_miss_its_node():
    off = {"degree": 1, "knotVector": [0, 0, 1, 1],
           "controlPoints": [{"x": 0.0, "y": 0.03}, {"x": 5.0, "y": 0.0}]}  # 3 cm off N0
    doc = with_(straight_order(), ("edges", 0, "trajectory"), off)
    with pytest.raises(InvalidInputError, match=re.escape(
            "`edges[0].trajectory` starts at (0, 0.03), 0.03 m from `nodes[0]` ('N0')")):
        Route.from_vda5050(doc)  # no deviation given: 1 cm
    for key in ("allowedDeviationXY", "allowedDeviationXy"):  # 2.0 spec / schema spelling
        ok = with_(doc, ("nodes", 0, "nodePosition", key), 0.05)
        assert Route.from_vda5050(ok).nodes[0].allowed_deviation_xy == 0.05
    v3 = with_(doc, ("version",), "3.0.0")
    for e in v3["edges"]:
        del e["startNodeId"], e["endNodeId"]
    v3["nodes"][0]["nodePosition"]["allowedDeviationXY"] = {"a": 0.2, "b": 0.04, "theta": 0.3}
    assert Route.from_vda5050(v3).nodes[0].allowed_deviation_xy == 0.04  # min(a, b)
    v3["nodes"][0]["nodePosition"]["allowedDeviationXY"] = {"a": 0.2, "b": 0.02, "theta": 0.3}
    with pytest.raises(InvalidInputError, match=r"`edges\[0\]\.trajectory` starts"):
        Route.from_vda5050(v3)
    end_off = with_(straight_order(), ("edges", 0, "trajectory"), LINE_TRAJ)
    end_off["edges"][0]["trajectory"]["controlPoints"][1]["x"] = 4.9
    with pytest.raises(InvalidInputError, match=r"`edges\[0\]\.trajectory` ends.*`nodes\[1\]`"):
        Route.from_vda5050(end_off)


def test_order_as_dict_json_text_or_file(tmp_path):
    doc = straight_order()
    f = tmp_path / "o.json"
    f.write_text(json.dumps(doc))
    lengths = [Route.from_vda5050(x).length for x in (doc, json.dumps(doc), f, str(f))]
    assert lengths == [10.0] * 4
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(with_(doc, ("edges", 1, "maxSpeed"), -1)))
    with pytest.raises(InvalidInputError, match=r"^bad\.json: `edges\[1\]\.maxSpeed` must be > 0"):
        Route.from_vda5050(bad)
    with pytest.raises(InvalidInputError, match="does not exist"):
        Route.from_vda5050(tmp_path / "none.json")
    with pytest.raises(InvalidInputError, match="not valid JSON"):
        Route.from_vda5050("{nodes")
    with pytest.raises(InvalidInputError, match="`order` must be"):
        Route.from_vda5050(42)  # type: ignore[arg-type]


# ---- malformed orders: each refused, the element named -------------------------------------------
def _traj_order(traj):
    return with_(straight_order(), ("edges", 0, "trajectory"), traj)


def _nan_order():
    doc = straight_order()
    doc["nodes"][1]["nodePosition"]["x"] = float("nan")
    return json.loads(json.dumps(doc))  # NaN survives Python's JSON, as many encoders emit it


def _v3(doc):
    doc = with_(doc, ("version",), "3.0.0")
    for e in doc["edges"]:
        e.pop("startNodeId", None)
        e.pop("endNodeId", None)
    return doc


MALFORMED = [
    # links between edges and nodes
    ("unknown start node", with_(straight_order(), ("edges", 1, "startNodeId"), "X"),
     "`edges[1].startNodeId` names node 'X', which is not in `nodes`"),
    ("start node is not the previous node", with_(straight_order(), ("edges", 1, "startNodeId"),
                                                 "N0"),
     "`edges[1].startNodeId` is 'N0' but the node before it in the order is `nodes[1]` ('N1')"),
    ("end node is not the next node", with_(straight_order(), ("edges", 0, "endNodeId"), "N2"),
     "`edges[0].endNodeId` is 'N2' but the node after it in the order is `nodes[1]`"),
    ("2.x edge without startNodeId", with_(straight_order(), ("edges", 0, "startNodeId"),
                                          KeyError),
     "`edges[0].startNodeId` is missing (required in VDA 5050 2.0)"),
    ("too many edges", with_(straight_order(), ("edges",), [edge(0), edge(1), edge(2)]),
     "`edges`: 3 nodes need 2 edges"),
    ("a single node", with_(with_(straight_order(), ("nodes",), [node(0, 0, 0)]), ("edges",), []),
     "`nodes`: the order has 1 node(s)"),
    # sequence ids
    ("odd first node", _v3({**straight_order(), "nodes": [
        {**n, "sequenceId": n["sequenceId"] + 1} for n in straight_order()["nodes"]]}),
     "`nodes[0].sequenceId` must be even"),
    ("node out of order", with_(straight_order(), ("nodes", 1, "sequenceId"), 6),
     "`nodes[1].sequenceId` must be 2"),
    ("edge out of order", with_(straight_order(), ("edges", 1, "sequenceId"), 1),
     "`edges[1].sequenceId` must be 3"),
    ("sequenceId as text", with_(straight_order(), ("nodes", 2, "sequenceId"), "4"),
     "`nodes[2].sequenceId` must be an integer >= 0; got '4'"),
    # geometry
    ("straight edge without positions", with_(straight_order(), ("nodes", 2, "nodePosition"),
                                             KeyError),
     "`edges[1]` has no trajectory and `nodes[2]` ('N2') has no nodePosition"),
    ("coincident nodes", with_(straight_order(), ("nodes", 2, "nodePosition", "x"), 5.0),
     "`edges[1]` has no trajectory and its nodes `nodes[1]` ('N1') and `nodes[2]` ('N2') are at "
     "the same position"),
    ("maps differ", with_(straight_order(), ("nodes", 2, "nodePosition", "mapId"), "hall-2"),
     "`nodes[2].nodePosition.mapId` 'hall-2' differs from 'hall' of `nodes[1]`"),
    ("trajectory not an object", _traj_order([1, 2]), "`edges[0].trajectory` must be a JSON "
     "object"),
    ("no control points", _traj_order({"degree": 1, "knotVector": [0, 1]}),
     "`edges[0].trajectory`: `controlPoints` is missing"),
    ("control point lacks y", _traj_order({**LINE_TRAJ, "controlPoints": [{"x": 0}, {"x": 5,
                                                                                    "y": 0}]}),
     "`edges[0].trajectory`: `controlPoints[0]` lacks 'y'"),
    ("control point as text", _traj_order({**LINE_TRAJ, "controlPoints": [
        {"x": "0", "y": 0}, {"x": 5, "y": 0}]}),
     "`edges[0].trajectory`: `controlPoints[0].x` must be a number; got '0'"),
    ("weight zero", _traj_order({**LINE_TRAJ, "controlPoints": [
        {"x": 0, "y": 0, "weight": 0}, {"x": 5, "y": 0}]}),
     "`edges[0].trajectory`: `controlPoints[0].weight` must be > 0"),
    ("fractional degree", _traj_order({**LINE_TRAJ, "degree": 1.5}),
     "`edges[0].trajectory`: `degree` must be an integer >= 1; got 1.5"),
    ("knot vector too short", _traj_order({**LINE_TRAJ, "knotVector": [0, 0, 1]}),
     "`edges[0].trajectory`: `knots` must have len(control_points) + degree + 1 = 4 entries"),
    ("knot vector as text", _traj_order({**LINE_TRAJ, "knotVector": "0 0 1 1"}),
     "`edges[0].trajectory`: `knotVector` must be a JSON array"),
    # limits
    ("negative speed", with_(straight_order(), ("edges", 0, "maxSpeed"), -1.0),
     "`edges[0].maxSpeed` must be > 0; got -1.0"),
    ("zero speed", with_(_v3(straight_order()), ("edges", 1, "maximumSpeed"), 0),
     "`edges[1].maximumSpeed` must be > 0; got 0"),
    ("infinite speed", with_(straight_order(), ("edges", 0, "maxSpeed"), float("inf")),
     "`edges[0].maxSpeed` must be a finite number; got inf"),
    ("speed as text", with_(straight_order(), ("edges", 0, "maxSpeed"), "fast"),
     "`edges[0].maxSpeed` must be a number; got 'fast'"),
    ("zero rotation speed", with_(straight_order(), ("edges", 0, "maxRotationSpeed"), 0.0),
     "`edges[0].maxRotationSpeed` must be > 0"),
    ("NaN position", _nan_order(), "`nodes[1].nodePosition.x` must be a finite number; got nan"),
    ("orientation type", with_(straight_order(), ("edges", 0, "orientationType"), "LOCAL"),
     "`edges[0].orientationType` must be one of TANGENTIAL, GLOBAL; got 'LOCAL'"),
    ("orientation as bool", with_(straight_order(), ("edges", 0, "orientation"), True),
     "`edges[0].orientation` must be a number; got True"),
    ("negative length", with_(straight_order(), ("edges", 0, "length"), -5),
     "`edges[0].length` must be >= 0"),
    ("negative deviation", with_(straight_order(), ("nodes", 0, "nodePosition",
                                                    "allowedDeviationXY"), -0.1),
     "`nodes[0].nodePosition.allowedDeviationXY` must be >= 0"),
    ("both deviation spellings", with_(with_(straight_order(), ("nodes", 0, "nodePosition",
                                                                "allowedDeviationXY"), 0.1),
                                       ("nodes", 0, "nodePosition", "allowedDeviationXy"), 0.2),
     "`nodes[0].nodePosition` gives both allowedDeviationXY and allowedDeviationXy"),
    ("3.0 deviation as a number", with_(_v3(straight_order()), ("nodes", 0, "nodePosition",
                                                                "allowedDeviationXY"), 0.1),
     "`nodes[0].nodePosition.allowedDeviationXY` must be an ellipse {a, b, theta} in VDA 5050 "
     "3.0"),
    # actions and types
    ("unknown blocking type", with_(straight_order(), ("nodes", 1, "actions"),
                                    [HARD | {"blockingType": "SINGLE"}]),
     "`nodes[1].actions[0].blockingType` must be one of NONE, SOFT, HARD in VDA 5050 2.0"),
    ("action without id", with_(straight_order(), ("nodes", 1, "actions"),
                                [{"actionType": "pick", "blockingType": "HARD"}]),
     "`nodes[1].actions[0].actionId` is missing"),
    ("actions not a list", with_(straight_order(), ("edges", 0, "actions"), {"a": 1}),
     "`edges[0].actions` must be a JSON array"),
    ("nodeId as number", with_(straight_order(), ("nodes", 0, "nodeId"), 7),
     "`nodes[0].nodeId` must be a string; got 7"),
    ("released as text", with_(straight_order(), ("edges", 0, "released"), "yes"),
     "`edges[0].released` must be true or false; got 'yes'"),
    ("node not an object", with_(straight_order(), ("nodes", 1), "N1"),
     "`nodes[1]` must be a JSON object; got str"),
    ("nodes not a list", with_(straight_order(), ("nodes",), {"N0": {}}),
     "`nodes` must be a JSON array"),
    ("orderUpdateId negative", with_(straight_order(), ("orderUpdateId",), -1),
     "`orderUpdateId` must be an integer >= 0"),
    ("headerId as text", with_(straight_order(), ("headerId",), "1"),
     "`headerId` must be an integer >= 0; got '1'"),
    ("serialNumber as number", with_(straight_order(), ("serialNumber",), 42),
     "`serialNumber` must be a string; got 42"),
    # released base
    ("first node in the horizon", with_(straight_order(), ("nodes", 0, "released"), False),
     "`nodes[0].released` must be true"),
    ("released after the horizon", with_(with_(straight_order(), ("edges", 0, "released"), False),
                                         ("nodes", 1, "released"), False),
     "`edges[1].released` is true after `edges[0]`, which is in the horizon"),
    ("edge released, end node not", with_(straight_order(), ("nodes", 2, "released"), False),
     "`edges[1]` is released but its end node `nodes[2]` is not"),
    # header
    ("no version", with_(straight_order(), ("version",), KeyError), "`order.version` is missing"),
    ("unsupported version", with_(straight_order(), ("version",), "1.1.0"),
     "`version` '1.1.0' is not supported; VDA 5050 orders of version 2.0.x, 2.1.x, 3.0.x"),
    ("not an order", [straight_order()], "`order` must be a dict, a JSON string or the path"),
]


@pytest.mark.parametrize(("doc", "message"), [m[1:] for m in MALFORMED],
                         ids=[m[0] for m in MALFORMED])
def test_malformed_orders_are_refused_naming_the_element(doc, message):
    with pytest.raises(InvalidInputError) as info:
        Route.from_vda5050(doc)
    assert message in str(info.value)


def test_an_order_with_no_released_edge_is_refused():
    doc = straight_order()
    for item in (doc["edges"][0], doc["edges"][1], doc["nodes"][1], doc["nodes"][2]):
        item["released"] = False
    with pytest.raises(InvalidInputError, match="`edges`: no edge is released"):
        Route.from_vda5050(doc)

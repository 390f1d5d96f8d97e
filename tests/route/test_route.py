"""Route built in Python: validation, planning quantities, stops and legs.

Oracles: polylines whose lengths and turning angles come from hypot / atan2 on the waypoints.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shared import examples

from speedplan import InvalidInputError
from speedplan.geometry import Arc, Line, Path
from speedplan.route import HEADING_TOLERANCE, Route, RouteEdge, RouteNode


def polyline_route(points, **edge_fields):
    """Straight edges through ``points``; every node has its position."""
    nodes = [RouteNode(f"N{i}", 2 * i, (float(x), float(y))) for i, (x, y) in enumerate(points)]
    edges = []
    for i, ((x0, y0), (x1, y1)) in enumerate(itertools.pairwise(points)):
        path = Path.from_segments([Line(math.hypot(x1 - x0, y1 - y0))], start=(x0, y0),
                                  heading=math.atan2(y1 - y0, x1 - x0))
        edges.append(RouteEdge(f"E{i}", 2 * i + 1, f"N{i}", f"N{i + 1}", path, **edge_fields))
    return nodes, edges


@settings(max_examples=examples(40), deadline=None)
@given(st.lists(st.tuples(st.integers(-20, 20), st.integers(-20, 20)), min_size=2, max_size=7,
                unique=True))
def test_polyline_route_lengths_node_positions_and_corner_stops(points):
    # Consecutive distinct points only (a zero-length edge is no path).
    pts = [p for i, p in enumerate(points) if i == 0 or p != points[i - 1]]
    route = Route(*polyline_route(pts))
    legs = np.hypot(*np.diff(np.array(pts, float), axis=0).T)
    np.testing.assert_allclose(route.node_s, np.concatenate(([0], np.cumsum(legs))), rtol=1e-14)
    assert route.length == pytest.approx(legs.sum(), rel=1e-14)
    assert route.edge_spans == tuple(zip(route.node_s[:-1], route.node_s[1:], strict=True))
    # The oracle for stops: the turning angle at each inner waypoint, from atan2 directly.
    d = np.diff(np.array(pts, float), axis=0)
    turn = np.abs(np.angle(np.exp(1j * np.diff(np.arctan2(d[:, 1], d[:, 0])))))
    expected = [0] + [i + 1 for i, a in enumerate(turn) if a > HEADING_TOLERANCE] + [len(legs)]
    np.testing.assert_array_equal(route.stop_s, route.node_s[expected])
    # The legs partition the edges in order, leg j between stop j and stop j + 1.
    got = route.legs()
    assert [e for leg in got for e in leg] == list(route.edges)
    for j, leg in enumerate(got):
        first, last = route.edges.index(leg[0]), route.edges.index(leg[-1])
        assert (route.node_s[first], route.node_s[last + 1]) == (route.stop_s[j],
                                                                 route.stop_s[j + 1])


def test_smooth_join_does_not_stop_and_a_reverse_edge_does():
    line = Path.from_segments([Line(3.0)])
    arc = Path.from_segments([Arc(2.0, math.pi / 2)], start=(3.0, 0.0))  # tangent to the line
    nodes = [RouteNode("A", 0, (0, 0)), RouteNode("B", 2, (3, 0)), RouteNode("C", 4, (5, 2))]
    smooth = Route(nodes, [RouteEdge("AB", 1, "A", "B", line), RouteEdge("BC", 3, "B", "C", arc)])
    assert smooth.stop_s.tolist() == [0.0, smooth.length]
    backwards = Route(nodes, [RouteEdge("AB", 1, "A", "B", line),
                              RouteEdge("BC", 3, "B", "C", arc, reverse=True)])
    assert backwards.stop_s.tolist() == [0.0, 3.0, backwards.length]


def test_route_arrays_are_read_only():
    route = Route(*polyline_route([(0, 0), (4, 0), (4, 3)]))
    for arr in (route.node_s, route.stop_s):
        with pytest.raises(ValueError, match="read-only"):
            arr[0] = 1.0


@pytest.mark.parametrize(("build", "message"), [
    (lambda n, e: (n, e[:1]), "`edges`: 3 nodes need 2 edges"),
    (lambda n, e: (n[:1], []), "`nodes`: a route needs at least two nodes"),
    (lambda n, e: (n, [e[0], RouteEdge("E1", 3, "N0", "N2", e[1].path)]),
     "`edges[1].start_node` must be 'N1', the node_id of `nodes[1]`; got 'N0'"),
    (lambda n, e: (n, [e[0], RouteEdge("E1", 5, "N1", "N2", e[1].path)]),
     "`edges[1].sequence_id` must be 3"),
    (lambda n, e: (n, [e[1], e[1]]), "`edges[0].sequence_id` must be 1"),
    (lambda n, e: (n, [e[0], "E1"]), "`edges[1]` must be a RouteEdge; got str"),
    (lambda n, e: ([n[0], RouteNode("N1", 2, (4.0, 0.5)), n[2]], e),
     "`edges[0].path` ends at (4, 0), 0.5 m from `nodes[1]` ('N1') at (4, 0.5)"),
    (lambda n, e: ([n[0], n[1], RouteNode("N2", 4, (4.0, 3.0), released=False)], e),
     "`edges[1]` is released but its end node `nodes[2]` is not"),
    (lambda n, e: (n, [e[0], RouteEdge("E1", 3, "N1", "N2", e[1].path, released=False)]),
     "`nodes[2].released` is true after `edges[1]`, which is in the horizon"),
])
def test_route_construction_is_validated(build, message):
    nodes, edges = polyline_route([(0, 0), (4, 0), (4, 3)])
    with pytest.raises(InvalidInputError) as info:
        Route(*build(nodes, edges))
    assert message in str(info.value)


def test_paths_must_meet_at_a_node_without_position():
    a = Path.from_segments([Line(4.0)])
    b = Path.from_segments([Line(3.0)], start=(4.0, 0.02))  # 2 cm off
    nodes = [RouteNode("A", 0), RouteNode("B", 2), RouteNode("C", 4)]
    edges = [RouteEdge("AB", 1, "A", "B", a), RouteEdge("BC", 3, "B", "C", b)]
    with pytest.raises(InvalidInputError, match=r"`edges\[1\]\.path` starts at \(4, 0\.02\)"):
        Route(nodes, edges)
    nodes[1] = RouteNode("B", 2, allowed_deviation_xy=0.05)
    assert Route(nodes, edges).length == 7.0


@pytest.mark.parametrize(("make", "message"), [
    (lambda p: RouteEdge("E", 1, "A", "B", p, v_max=-1.0), "`v_max` must be > 0"),
    (lambda p: RouteEdge("E", 1, "A", "B", p, yaw_rate_max=float("nan")),
     "`yaw_rate_max` must be a finite number"),
    (lambda p: RouteEdge("E", 1, "A", "B", "path"), "`path` must be a speedplan.Path"),
    (lambda p: RouteEdge("E", 1, "A", "B", p, reverse=1), "`reverse` must be true or false"),
    (lambda p: RouteEdge(3, 1, "A", "B", p), "`edge_id` must be a string"),
    (lambda p: RouteNode("A", -2), "`sequence_id` must be an integer >= 0"),
    (lambda p: RouteNode("A", 0, position=(1.0,)), "`position` must be (x, y) or None"),
    (lambda p: RouteNode("A", 0, position=(1.0, float("inf"))), "`position[1]` must be a finite"),
    (lambda p: RouteNode("A", 0, allowed_deviation_xy=-0.1),
     "`allowed_deviation_xy` must be >= 0.0"),
])
def test_node_and_edge_fields_are_validated(make, message):
    with pytest.raises(InvalidInputError) as info:
        make(Path.from_segments([Line(1.0)]))
    assert message in str(info.value)

"""Route: a chain of edges between nodes, with per-edge limits and the places to stop."""

from __future__ import annotations

import itertools
import os
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from ..core.checks import FloatArray, instances
from ..core.errors import InvalidInputError
from ..core.numerics import wrap_angle
from ..core.options import JsonObject
from ..geometry import Path
from ..geometry.corners import CUSP_ANGLE, g2_chain
from . import _checks
from ._checks import integer, string
from .elements import THETA_TOLERANCE, RouteEdge, RouteNode
from .vda5050 import read_order

__all__ = ["HEADING_TOLERANCE", "THETA_TOLERANCE", "Route", "RouteEdge", "RouteNode"]

#: A heading change [rad] larger than this where two edges meet makes the vehicle stop there.
HEADING_TOLERANCE = 1e-6


def _heading_change(incoming: Path, outgoing: Path) -> float:
    """|heading jump| [rad] from the end of ``incoming`` to the start of ``outgoing``."""
    before = float(incoming.heading(incoming.length))
    after = float(outgoing.heading(0.0))
    return float(abs(wrap_angle(after - before)))


def _is_straight(path: Path) -> bool:
    """Whether ``path`` is one straight piece driven forward (an edge between node positions)."""
    return len(path.pieces) == 1 and path.pieces[0].straight and path.pieces[0].direction == 1


def _turn(before: RouteEdge, after: RouteEdge) -> float:
    """Signed change [rad] of the vehicle's heading from ``before``'s end to ``after``'s start."""
    return float(wrap_angle(after.heading(True) - before.heading(False)))


def corner_deviation(before: RouteEdge, node: RouteNode, after: RouteEdge) -> float:
    """How far [m] a rounded corner on ``node`` may pass from it.

    The corner's point nearest the node lies on the inner bisector of the two edges: it must
    lie inside the node's allowed deviation (the 3.0 ellipse's radius in that direction) and,
    at ``d cos(δ/2)`` from each edge's line for a turn ``δ``, inside the inner side of each
    edge's [`corridor`][speedplan.route.RouteEdge].
    """
    d_in = float(before.path.heading(before.path.length))
    d_out = float(after.path.heading(0.0))
    delta = float(wrap_angle(d_out - d_in))
    inner = d_in + 0.5 * delta + (np.pi / 2 if delta > 0 else -np.pi / 2)
    dev = node.deviation_towards(inner)
    side = 0 if delta > 0 else 1  # a left turn cuts into the corridors' left sides
    for edge in (before, after):
        if edge.corridor is not None:
            dev = min(dev, edge.corridor[side] / np.cos(0.5 * delta))
    return float(dev)


def _can_round(before: RouteEdge, node: RouteNode, after: RouteEdge) -> bool:
    """Whether the corner on ``node`` between two straight edges is rounded (G2).

    Both edges run straight between node positions, the corner may pass the node at some
    distance (`corner_deviation`), the turn is not a reversal
    (`CUSP_ANGLE`), the vehicle keeps its driving
    direction, may rotate on both edges and need not reach the next edge's heading before
    entering it, and the corner's heading on the node meets the node's ``theta``.
    """
    if not (_is_straight(before.path) and _is_straight(after.path)
            and before.reverse == after.reverse and before.rotation_allowed
            and after.rotation_allowed and not after.turn_before_entering
            and _heading_change(before.path, after.path) <= CUSP_ANGLE
            and corner_deviation(before, node, after) > 0.0):
        return False
    if node.theta is None:
        return True
    middle = before.heading(True) + 0.5 * _turn(before, after)
    return abs(float(wrap_angle(node.theta - middle))) <= node.theta_tolerance


def _join_at_node(before: RouteEdge, node: RouteNode, after: RouteEdge) -> bool:
    """Whether the vehicle must stop on ``node`` to pass from ``before`` to ``after``.

    The one place that decides how a route passes a node between two edges: where the
    heading changes by more than `HEADING_TOLERANCE`, the corner is rounded within
    the node's allowed deviation and the edges' corridors when `_can_round` allows it
    (a G2 clothoid–arc–clothoid corner, as `Path.from_waypoints` builds them), else the
    vehicle stops there (it turns on the spot).
    """
    if _heading_change(before.path, after.path) <= HEADING_TOLERANCE:
        return False
    return not _can_round(before, node, after)


def _turn_headings(node: RouteNode, arrive: float | None, leave: float | None) -> list[float]:
    """Headings [rad] the vehicle stands at on ``node``: arriving, ``theta``, leaving.

    Consecutive entries differ by more than their tolerance (a heading within
    ``theta_tolerance`` of ``theta`` meets it); one entry: no turn.
    """
    first = arrive if arrive is not None else leave
    if first is None:
        return []
    out = [first]
    if node.theta is not None and abs(float(wrap_angle(node.theta - first))) \
            > node.theta_tolerance:
        out.append(node.theta)
    if leave is not None and abs(float(wrap_angle(leave - out[-1]))) > HEADING_TOLERANCE:
        out.append(leave)
    return [float(h) for h in out]


@dataclass(frozen=True, eq=False)
class Route:
    """A route: nodes and the edges between them, as in a VDA 5050 order.

    ``edges[i]`` runs from ``nodes[i]`` to ``nodes[i + 1]``. The planning quantities
    ([`length`][speedplan.Route.length], `node_s`, `edge_spans`, `stop_s`, `legs`) cover
    the **released base** only — the vehicle plans it and must be able to stop at its end;
    the horizon (``released`` false) is kept in [`nodes`][speedplan.Route] and `edges` for
    information. Arc length ``s`` [m] runs along the base from its first node; the edges'
    paths are chained end to start (each within its node's allowed deviation of the next).

    The vehicle stops (v = 0, a = 0) at the start, at the last released node, on every node
    with a blocking (SOFT or HARD) action, at the start node of an edge with such an action,
    where the driving direction changes (an edge driven backwards after one driven forwards,
    or the reverse: a cusp) and where the heading jumps between two edges (see
    `HEADING_TOLERANCE`).

    Parameters
    ----------
    nodes : sequence of RouteNode
        At least two; the first is released.
    edges : sequence of RouteEdge
        ``len(nodes) - 1`` edges, at least the first released.
    order_id, order_update_id, version : optional
        The order's ``orderId``, ``orderUpdateId`` and protocol ``version`` when read from one.
    notes : tuple of str
        What of the order the planner does not honour as written, one line per field naming
        its node or edge and why (`from_vda5050` also warns them, once per order).

    Raises
    ------
    InvalidInputError
        Wrong types, sequence ids that do not alternate (nodes even, edges odd), an edge that
        does not join the nodes around it, a broken released base, or edge paths that do not
        meet their nodes within the allowed deviation (at least 1 cm).

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.geometry import Line, Path
    >>> from speedplan.route import Route, RouteEdge, RouteNode
    >>> nodes = [RouteNode("A", 0, (0.0, 0.0)), RouteNode("B", 2, (4.0, 0.0), stop=True),
    ...          RouteNode("C", 4, (4.0, 3.0))]
    >>> edges = [RouteEdge("AB", 1, "A", "B", Path.from_segments([Line(4.0)])),
    ...          RouteEdge("BC", 3, "B", "C", Path.from_segments([Line(3.0)], start=(4, 0),
    ...                                                          heading=np.pi / 2))]
    >>> r = Route(nodes, edges)
    >>> r.length, r.node_s.tolist(), r.stop_s.tolist()
    (7.0, [0.0, 4.0, 7.0], [0.0, 4.0, 7.0])
    >>> [[e.edge_id for e in leg] for leg in r.legs()]
    [['AB'], ['BC']]
    """

    nodes: tuple[RouteNode, ...]
    edges: tuple[RouteEdge, ...]
    order_id: str | None = None
    order_update_id: int | None = None
    version: str | None = None
    notes: tuple[str, ...] = ()
    _stops: tuple[tuple[int, str], ...] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "nodes", tuple(instances("nodes", self.nodes, RouteNode)))
        object.__setattr__(self, "edges", tuple(instances("edges", self.edges, RouteEdge)))
        if len(self.nodes) < 2:
            raise InvalidInputError(
                f"`nodes`: a route needs at least two nodes (and an edge); got {len(self.nodes)}"
            )
        _checks.check_sequence([n.sequence_id for n in self.nodes],
                               [e.sequence_id for e in self.edges], "sequence_id")
        _checks.check_released([n.released for n in self.nodes], [e.released for e in self.edges])
        for i, e in enumerate(self.edges):
            for attr, j in (("start_node", i), ("end_node", i + 1)):
                if getattr(e, attr) != self.nodes[j].node_id:
                    raise InvalidInputError(
                        f"`edges[{i}].{attr}` must be {self.nodes[j].node_id!r}, the node_id of "
                        f"`nodes[{j}]`; got {getattr(e, attr)!r}"
                    )
            self._check_ends(i, e)
        for name, value in (("order_id", self.order_id), ("version", self.version)):
            if value is not None:
                string(value, name)
        if self.order_update_id is not None:
            integer(self.order_update_id, "order_update_id")
        object.__setattr__(self, "notes", tuple(string(note, f"notes[{i}]")
                                                for i, note in enumerate(self.notes)))
        object.__setattr__(self, "_stops", self._find_stops())

    def _check_ends(self, i: int, edge: RouteEdge) -> None:
        """The edge's path meets its nodes (by position, or the neighbouring path's end)."""
        ends = edge.path.point(np.array([0.0, edge.path.length]))
        for j, end, verb in ((i, ends[0], "starts"), (i + 1, ends[1], "ends")):
            node = self.nodes[j]
            tol = _checks.node_tolerance(node.allowed_deviation_xy)
            label = f"`nodes[{j}]` ({node.node_id!r})"
            if node.position is not None:
                _checks.check_meets_node(end, node.position, tol, f"`edges[{i}].path` {verb}",
                                         label)
            elif verb == "starts" and i > 0:  # no position: the two paths must meet
                prev = self.edges[i - 1].path
                meet = prev.point(prev.length)
                _checks.check_meets_node(
                    end, (float(meet[0]), float(meet[1])), tol, f"`edges[{i}].path` {verb}",
                    f"the end of `edges[{i - 1}].path` at {label} (no position)")

    def _find_stops(self) -> tuple[tuple[int, str], ...]:
        """``(base node index, reason)`` of every stop, in order along the base."""
        edges, nodes = self.base_edges, self.base_nodes
        stops = [(0, "; ".join(filter(None, ("start", self._turn_reason(0)))))]
        for i in range(1, len(edges)):
            node, before, after = nodes[i], edges[i - 1], edges[i]
            reasons = []
            if node.stop:
                reasons.append(f"node {node.node_id!r} has a blocking (SOFT/HARD) action")
            if after.stop:
                reasons.append(f"edge {after.edge_id!r} has a blocking (SOFT/HARD) action")
            if before.reverse != after.reverse:
                reasons.append("the driving direction changes (cusp)")
            if _join_at_node(before, node, after):
                turn = _heading_change(before.path, after.path)
                reasons.append(f"the heading changes by {turn:.3g} rad")
            elif (why := self._turn_reason(i)) is not None:
                reasons.append(why)
            if reasons:
                stops.append((i, "; ".join(reasons)))
        end = len(edges)
        stops.append((end, "; ".join(filter(None, ("end of the released base",
                                                   self._turn_reason(end))))))
        return tuple(stops)

    def _turn_reason(self, k: int) -> str | None:
        """Why the vehicle turns on the spot on released node ``k`` (``None``: it does not)."""
        heads, node = self.turn_headings[k], self.base_nodes[k]
        if len(heads) < 2:
            return None
        if node.theta is not None and any(
                abs(float(wrap_angle(node.theta - h))) <= node.theta_tolerance
                for h in heads[1:]):
            return f"the vehicle turns on the spot to theta = {node.theta:.6g} rad"
        return f"the vehicle turns on the spot by {float(wrap_angle(heads[-1] - heads[0])):.3g} rad"

    @cached_property
    def _round_set(self) -> frozenset[int]:
        return frozenset(self.rounded_nodes)

    @cached_property
    def turn_headings(self) -> tuple[tuple[float, ...], ...]:
        """Per released node, the headings [rad] the vehicle turns through on it, standing.

        The heading it arrives with, the node's ``theta`` where that differs by more than
        `RouteNode.theta_tolerance`, and the heading the next edge starts with
        (the vehicle's: the tangent, plus π on an edge driven backwards); one entry where it
        does not turn, none on a rounded node. On the first node the vehicle is taken to
        stand at its ``theta`` (else at the first edge's heading); on the last it turns to
        its ``theta``.
        """
        return tuple(() if k in self._round_set else self.node_headings(k)
                     for k in range(len(self.base_nodes)))

    def node_headings(self, k: int, arrive: float | None = None) -> tuple[float, ...]:
        """[`turn_headings`][speedplan.Route] of released node ``k`` for a given arrival heading.

        ``arrive`` [rad] defaults to the heading of the edge into the node; on the first node
        to its ``theta``, else the first edge's heading.
        """
        edges, node = self.base_edges, self.base_nodes[k]
        leave = edges[k].heading(False) if k < len(edges) else None
        if arrive is None:
            arrive = edges[k - 1].heading(True) if k > 0 else (
                node.theta if node.theta is not None else leave)
        return tuple(_turn_headings(node, arrive, leave))

    def turn_rate_limit(self, k: int) -> float:
        """Yaw-rate limit [rad/s] of a turn on released node ``k``.

        The smaller ``yaw_rate_max`` (``maxRotationSpeed``) of the edges into and out of it;
        ``inf`` when neither gives one.
        """
        edges = self.base_edges
        near = [edges[j].yaw_rate_max for j in (k - 1, k) if 0 <= j < len(edges)]
        return float(min((r for r in near if r is not None), default=np.inf))

    # ---- the released base ------------------------------------------------------------------
    @cached_property
    def base_edges(self) -> tuple[RouteEdge, ...]:
        """The released edges (a prefix of [`edges`][speedplan.Route])."""
        return tuple(e for e in self.edges if e.released)

    @property
    def base_nodes(self) -> tuple[RouteNode, ...]:
        """The released nodes (a prefix of `nodes`, one more than `base_edges`)."""
        return self.nodes[: len(self.base_edges) + 1]

    @cached_property
    def _geometry(self) -> tuple[Path, FloatArray, tuple[int, ...]]:
        """The base as one path, the arc length of each released node, the rounded nodes."""
        edges, nodes = self.base_edges, self.base_nodes
        pieces: list[Any] = []
        node_s = np.zeros(len(nodes))
        rounded: list[int] = []
        i = 0
        while i < len(edges):
            # A run of straight edges whose inner nodes are all rounded: one G2 chain.
            j = i
            while j + 1 < len(edges) and _heading_change(edges[j].path, edges[j + 1].path) \
                    > HEADING_TOLERANCE and _can_round(edges[j], nodes[j + 1], edges[j + 1]):
                j += 1
            offset = float(sum(p.length for p in pieces))
            if j > i:
                pts = np.array([e.path.point(0.0) for e in edges[i:j + 1]]
                               + [edges[j].path.point(edges[j].path.length)])
                dev = np.zeros(j - i + 2)
                for k in range(i + 1, j + 1):
                    dev[k - i] = corner_deviation(edges[k - 1], nodes[k], edges[k])
                chain, at = g2_chain(pts, dev)
                run = Path(chain)
                if edges[i].reverse:
                    run = run.reversed(swap_direction=True).reversed()
                pieces += run.pieces
                node_s[i + 1:j + 2] = offset + at[1:]
                rounded += list(range(i + 1, j + 1))
            else:
                path = edges[i].path
                if edges[i].reverse:
                    path = path.reversed(swap_direction=True).reversed()
                pieces += path.pieces
                node_s[i + 1] = offset + path.length
            i = j + 1
        node_s.flags.writeable = False
        return Path(tuple(pieces)), node_s, tuple(rounded)

    @property
    def path(self) -> Path:
        """The released base as one [`Path`][speedplan.Path]: what ``plan_route`` plans.

        The edges' paths in order (driven in reverse where the edge says so), with the corners
        between straight edges rounded within their node's allowed deviation.
        """
        return self._geometry[0]

    @property
    def node_s(self) -> FloatArray:
        """Arc length [m] of each released node along [`path`][speedplan.Route.path].

        0 first, `length` last; on a rounded corner, the corner's middle (its point
        nearest the node).
        """
        return self._geometry[1]

    @property
    def rounded_nodes(self) -> tuple[int, ...]:
        """Indices of the released nodes whose corner is rounded (see `path`)."""
        return self._geometry[2]

    @property
    def length(self) -> float:
        """Length of the released base [m].

        The sum of its edges' lengths, less what the rounded corners cut.
        """
        return float(self.node_s[-1])

    @property
    def edge_spans(self) -> tuple[tuple[float, float], ...]:
        """``(s_start, s_end)`` [m] of each released edge along the base."""
        s = self.node_s
        return tuple((float(s[i]), float(s[i + 1])) for i in range(len(self.base_edges)))

    @cached_property
    def stop_s(self) -> FloatArray:
        """Positions [m] where the vehicle must stop (v = 0, a = 0), start and end included.

        Stops are at nodes; ``stop_s[j]`` and ``stop_s[j + 1]`` bound ``legs()[j]``.
        """
        out = self.node_s[[i for i, _ in self._stops]]
        out.flags.writeable = False
        return out

    @property
    def stop_reasons(self) -> tuple[str, ...]:
        """Why the vehicle stops at each entry of [`stop_s`][speedplan.Route.stop_s]."""
        return tuple(reason for _, reason in self._stops)

    def legs(self) -> list[tuple[RouteEdge, ...]]:
        """The released edges between consecutive stops, one tuple per stop-to-stop leg.

        A speed planner plans each leg from rest to rest; leg ``j`` spans
        ``[stop_s[j], stop_s[j + 1]]``.
        """
        cuts = [i for i, _ in self._stops]
        return [self.base_edges[a:b] for a, b in itertools.pairwise(cuts)]

    # ---- constructors -----------------------------------------------------------------------
    @classmethod
    def from_vda5050(cls, order: JsonObject | str | os.PathLike[str]) -> Route:
        """Read a VDA 5050 order (versions 2.0, 2.1 and 3.0).

        Parameters
        ----------
        order : dict, str or os.PathLike
            The parsed order, its JSON text (a string starting with ``{``) or a JSON file.

        Returns
        -------
        Route
            Edges with a ``trajectory`` become NURBS paths (3.0 defaults: ``degree`` 1,
            uniform clamped knots, weights 1); edges without one run straight between their
            node positions. See `speedplan.route.vda5050` for the fields read per version.

        Raises
        ------
        InvalidInputError
            The order is malformed; the message names the element, e.g.
            ``` `edges[1].trajectory`: ...```, and a file by its name.

        Examples
        --------
        >>> from speedplan.route import Route
        >>> order = {"version": "3.0.0", "nodes": [
        ...     {"nodeId": "A", "sequenceId": 0, "released": True, "actions": [],
        ...      "nodePosition": {"x": 0.0, "y": 0.0, "mapId": "m"}},
        ...     {"nodeId": "B", "sequenceId": 2, "released": True, "actions": [],
        ...      "nodePosition": {"x": 3.0, "y": 4.0, "mapId": "m"}}],
        ...     "edges": [{"edgeId": "AB", "sequenceId": 1, "released": True, "actions": [],
        ...                "maximumSpeed": 1.2}]}
        >>> r = Route.from_vda5050(order)
        >>> r.length, r.edges[0].v_max
        (5.0, 1.2)
        """
        order_read = read_order(order)
        return cls(order_read.nodes, order_read.edges, order_id=order_read.order_id,
                   order_update_id=order_read.order_update_id, version=order_read.version,
                   notes=order_read.notes)

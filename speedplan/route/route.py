"""Route: a chain of edges between nodes, with per-edge limits and the places to stop."""

from __future__ import annotations

import itertools
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from ..core.checks import FloatArray, instances
from ..core.errors import InvalidInputError
from ..geometry import Path
from ..geometry._checks import wrap_angle
from ..geometry.corners import CUSP_ANGLE, g2_chain
from ..geometry.primitives import ClothoidPiece
from . import _checks
from ._checks import boolean, integer, number, positive, string

__all__ = ["HEADING_TOLERANCE", "Route", "RouteEdge", "RouteNode"]

#: A heading change [rad] larger than this where two edges meet makes the vehicle stop there.
HEADING_TOLERANCE = 1e-6


def _limit(value: Any, where: str) -> float | None:
    """An optional limit: ``None`` (no limit) or a number > 0."""
    return None if value is None else positive(value, where)


def _distance(value: Any, where: str) -> float:
    """A number >= 0."""
    return number(value, where, minimum=0.0)


def _set_checked(obj: Any, **checks: Callable[[Any, str], Any]) -> None:
    """Replace each named field of the frozen dataclass ``obj`` by ``check(value, name)``."""
    for name, check in checks.items():
        object.__setattr__(obj, name, check(getattr(obj, name), name))


@dataclass(frozen=True)
class RouteNode:
    """A node of a route: where edges meet, actions run and the vehicle may have to stop.

    Attributes
    ----------
    node_id : str
        Identifier (VDA 5050 ``nodeId``; not necessarily unique: a route may pass a node twice).
    sequence_id : int
        Position in the order (VDA 5050 ``sequenceId``): nodes even, edges odd, alternating.
    position : (x, y) or None
        Node position [m] (``nodePosition``); ``None`` when the order gives none (allowed only
        between two edges with trajectories).
    theta : float or None
        Orientation the vehicle shall have on the node [rad] (``nodePosition.theta``); stored,
        not used by the route's stops.
    allowed_deviation_xy : float
        How far [m] the vehicle may pass from ``position`` (VDA 5050 2.x ``allowedDeviationXY``;
        for 3.0's ellipse the semi-minor axis, the largest circle inside it). 0 when not given.
    stop : bool
        The node carries an action with ``blockingType`` SOFT or HARD: driving is not allowed
        while it runs, so the vehicle stops on the node (v = 0, a = 0).
    released : bool
        Part of the base (``True``) or of the horizon.

    Examples
    --------
    >>> from speedplan.route import RouteNode
    >>> RouteNode("N1", 2, position=(3.0, 4.0), stop=True).stop
    True
    """

    node_id: str
    sequence_id: int
    position: tuple[float, float] | None = None
    theta: float | None = None
    allowed_deviation_xy: float = 0.0
    stop: bool = False
    released: bool = True

    def __post_init__(self) -> None:
        _set_checked(self, node_id=string, sequence_id=integer)
        if self.position is not None:
            pos = self.position
            if isinstance(pos, str) or not hasattr(pos, "__len__") or len(pos) != 2:
                raise InvalidInputError(f"`position` must be (x, y) or None; got {pos!r}")
            object.__setattr__(self, "position", (number(pos[0], "position[0]"),
                                                  number(pos[1], "position[1]")))
        if self.theta is not None:
            _set_checked(self, theta=number)
        _set_checked(self, allowed_deviation_xy=_distance, stop=boolean, released=boolean)


@dataclass(frozen=True, eq=False)
class RouteEdge:
    """An edge of a route: its geometry and its limits.

    Attributes
    ----------
    edge_id : str
        Identifier (VDA 5050 ``edgeId``).
    sequence_id : int
        Position in the order (odd: between the nodes ``sequence_id ∓ 1``).
    start_node, end_node : str
        ``node_id`` of the nodes it joins (``route.nodes[i]`` and ``route.nodes[i + 1]`` for
        ``route.edges[i]``).
    path : Path
        The edge's geometry in travel order, from its start node to its end node (also when
        the vehicle drives it backwards).
    v_max : float or None
        Speed limit on the edge [m/s] (VDA 5050 2.x ``maxSpeed``, 3.0 ``maximumSpeed``).
    yaw_rate_max : float or None
        Rotation-speed limit on the edge [rad/s] (``maxRotationSpeed``).
    reverse : bool
        The vehicle drives the edge backwards (``orientation`` with ``orientationType``
        TANGENTIAL, the default, pointing against the travel direction: ``|orientation| >
        π/2``).
    released : bool
        Part of the base (``True``) or of the horizon.
    stop : bool
        The edge carries an action with ``blockingType`` SOFT or HARD: it starts when the
        vehicle enters the edge and forbids driving while it runs, so the vehicle stops at
        the edge's start node.

    Examples
    --------
    >>> from speedplan.geometry import Line, Path
    >>> from speedplan.route import RouteEdge
    >>> e = RouteEdge("E1", 1, "N0", "N1", Path.from_segments([Line(5.0)]), v_max=1.2)
    >>> e.path.length, e.v_max, e.reverse
    (5.0, 1.2, False)
    """

    edge_id: str
    sequence_id: int
    start_node: str
    end_node: str
    path: Path
    v_max: float | None = None
    yaw_rate_max: float | None = None
    reverse: bool = False
    released: bool = True
    stop: bool = False

    def __post_init__(self) -> None:
        _set_checked(self, edge_id=string, sequence_id=integer, start_node=string,
                     end_node=string)
        if not isinstance(self.path, Path):
            raise InvalidInputError(
                f"`path` must be a speedplan.Path; got {type(self.path).__name__}"
            )
        _set_checked(self, v_max=_limit, yaw_rate_max=_limit, reverse=boolean, released=boolean,
                     stop=boolean)


def _heading_change(incoming: Path, outgoing: Path) -> float:
    """|heading jump| [rad] from the end of ``incoming`` to the start of ``outgoing``."""
    before = float(incoming.heading(incoming.length))
    after = float(outgoing.heading(0.0))
    return float(abs(wrap_angle(after - before)))


def _is_straight(path: Path) -> bool:
    """Whether ``path`` is one straight piece driven forward (an edge between node positions)."""
    if len(path.pieces) != 1:
        return False
    piece = path.pieces[0]
    return isinstance(piece, ClothoidPiece) and piece.k0 == 0.0 and piece.k1 == 0.0 \
        and piece.direction == 1


def _can_round(before: RouteEdge, node: RouteNode, after: RouteEdge) -> bool:
    """Whether the corner on ``node`` between two straight edges is rounded (G2).

    Both edges run straight between node positions, the node allows a deviation, the turn is
    not a reversal (`CUSP_ANGLE`) and the vehicle keeps
    its driving direction.
    """
    return (_is_straight(before.path) and _is_straight(after.path)
            and node.allowed_deviation_xy > 0.0 and before.reverse == after.reverse
            and _heading_change(before.path, after.path) <= CUSP_ANGLE)


def _join_at_node(before: RouteEdge, node: RouteNode, after: RouteEdge) -> bool:
    """Whether the vehicle must stop on ``node`` to pass from ``before`` to ``after``.

    The one place that decides how a route passes a node between two edges: where the
    heading changes by more than `HEADING_TOLERANCE`, the corner is rounded within
    ``node.allowed_deviation_xy`` when both edges are straight (`_can_round`: a G2
    clothoid–arc–clothoid corner, as `Path.from_waypoints` builds them), else the
    vehicle stops there (it turns on the spot).
    """
    if _heading_change(before.path, after.path) <= HEADING_TOLERANCE:
        return False
    return not _can_round(before, node, after)


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
        edges = self.base_edges
        stops = [(0, "start")]
        for i in range(1, len(edges)):
            node, before, after = self.nodes[i], edges[i - 1], edges[i]
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
            if reasons:
                stops.append((i, "; ".join(reasons)))
        stops.append((len(edges), "end of the released base"))
        return tuple(stops)

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
                dev = np.array([nodes[k].allowed_deviation_xy for k in range(i, j + 2)])
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
    def from_vda5050(cls, order: dict[str, Any] | str | os.PathLike[str]) -> Route:
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
        from .vda5050 import route_from_vda5050

        return route_from_vda5050(order)

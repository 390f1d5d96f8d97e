"""The elements of a route: nodes and the edges between them, each with its own limits."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.errors import InvalidInputError
from ..geometry import Path
from ._checks import boolean, integer, number, positive, string

__all__ = ["THETA_TOLERANCE", "RouteEdge", "RouteNode"]

#: How closely [rad] the vehicle meets a node's ``theta`` when the node gives no (or a zero)
#: ``allowedDeviationTheta``: 0.001 rad (0.06°), below what AGV localisation resolves.
THETA_TOLERANCE = 1e-3


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
        Heading the vehicle shall have on the node [rad] (``nodePosition.theta``): where the
        path's heading there differs by more than `theta_tolerance`, the vehicle stops
        on the node and turns to ``theta`` (and then to the next edge's heading).
    allowed_deviation_xy : float
        How far [m] the vehicle may pass from ``position`` (VDA 5050 2.x ``allowedDeviationXY``;
        for 3.0's ellipse the semi-minor axis, the largest circle inside it). 0 when not given.
    stop : bool
        The node carries an action with ``blockingType`` SOFT or HARD: driving is not allowed
        while it runs, so the vehicle stops on the node (v = 0, a = 0).
    released : bool
        Part of the base (``True``) or of the horizon.
    allowed_deviation_theta : float or None
        How far [rad] the heading may differ from ``theta`` (``allowedDeviationTheta``);
        ``None`` or 0: `THETA_TOLERANCE`.
    deviation_ellipse : (a, b, angle) or None
        VDA 5050 3.0's ``allowedDeviationXY`` ellipse: semi-axes ``a``, ``b`` [m] and the
        angle [rad] of the ``a`` axis to the map's x axis. A corner on the node is rounded
        so that its point nearest the node lies inside the ellipse.

    Examples
    --------
    >>> from speedplan.route import RouteNode
    >>> RouteNode("N1", 2, position=(3.0, 4.0), stop=True).stop
    True
    >>> RouteNode("N2", 4, position=(3.0, 9.0), theta=1.0).theta_tolerance
    0.001
    """

    node_id: str
    sequence_id: int
    position: tuple[float, float] | None = None
    theta: float | None = None
    allowed_deviation_xy: float = 0.0
    stop: bool = False
    released: bool = True
    allowed_deviation_theta: float | None = None
    deviation_ellipse: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        _set_checked(self, node_id=string, sequence_id=integer)
        if self.allowed_deviation_theta is not None:
            _set_checked(self, allowed_deviation_theta=_distance)
        if self.deviation_ellipse is not None:
            ell = self.deviation_ellipse
            if isinstance(ell, str) or not hasattr(ell, "__len__") or len(ell) != 3:
                raise InvalidInputError(
                    f"`deviation_ellipse` must be (a, b, angle) or None; got {ell!r}")
            object.__setattr__(self, "deviation_ellipse", (
                _distance(ell[0], "deviation_ellipse[0]"),
                _distance(ell[1], "deviation_ellipse[1]"),
                number(ell[2], "deviation_ellipse[2]")))
        if self.position is not None:
            pos = self.position
            if isinstance(pos, str) or not hasattr(pos, "__len__") or len(pos) != 2:
                raise InvalidInputError(f"`position` must be (x, y) or None; got {pos!r}")
            object.__setattr__(self, "position", (number(pos[0], "position[0]"),
                                                  number(pos[1], "position[1]")))
        if self.theta is not None:
            _set_checked(self, theta=number)
        _set_checked(self, allowed_deviation_xy=_distance, stop=boolean, released=boolean)

    @property
    def theta_tolerance(self) -> float:
        """How far [rad] the heading on the node may differ from `theta`."""
        return max(self.allowed_deviation_theta or 0.0, THETA_TOLERANCE)

    def deviation_towards(self, direction: float) -> float:
        """Allowed deviation [m] from the node in the map direction ``direction`` [rad].

        The ellipse's radius in that direction, else `allowed_deviation_xy`.
        """
        if self.deviation_ellipse is None:
            return self.allowed_deviation_xy
        a, b, angle = self.deviation_ellipse
        if a == 0.0 or b == 0.0:
            return 0.0
        phi = direction - angle
        return float(a * b / np.hypot(b * np.cos(phi), a * np.sin(phi)))


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
    rotation_allowed : bool
        Whether the vehicle may rotate while on the edge (VDA 5050 2.x ``rotationAllowed``,
        default ``True``). ``False``: no corner is rounded into or out of the edge; the vehicle
        stops on the nodes and turns there.
    turn_before_entering : bool
        The vehicle must have the edge's heading before it enters the edge (VDA 5050 3.0
        ``reachOrientationBeforeEntering``): no corner is rounded into it.
    corridor : (left, right) or None
        How far [m] the vehicle may leave the edge's geometry to its left and right, seen in
        the travel direction (VDA 5050 ``corridor`` ``leftWidth``, ``rightWidth``); a corner
        rounded on a node stays inside the corridors of both edges. ``None``: no corridor,
        only the nodes' allowed deviations bound a rounded corner.

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
    rotation_allowed: bool = True
    turn_before_entering: bool = False
    corridor: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        _set_checked(self, edge_id=string, sequence_id=integer, start_node=string,
                     end_node=string, rotation_allowed=boolean, turn_before_entering=boolean)
        if self.corridor is not None:
            c = self.corridor
            if isinstance(c, str) or not hasattr(c, "__len__") or len(c) != 2:
                raise InvalidInputError(f"`corridor` must be (left, right) or None; got {c!r}")
            object.__setattr__(self, "corridor", (_distance(c[0], "corridor[0]"),
                                                  _distance(c[1], "corridor[1]")))
        if not isinstance(self.path, Path):
            raise InvalidInputError(
                f"`path` must be a speedplan.Path; got {type(self.path).__name__}"
            )
        _set_checked(self, v_max=_limit, yaw_rate_max=_limit, reverse=boolean, released=boolean,
                     stop=boolean)

    def heading(self, at_end: bool) -> float:
        """The vehicle's heading [rad] at the edge's start (or end).

        The path's tangent, turned by π when the edge is driven backwards.
        """
        h = float(self.path.heading(self.path.length if at_end else 0.0))
        return h + np.pi if self.reverse else h

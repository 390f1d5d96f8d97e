"""Routes: chains of edges between nodes with per-edge limits and stops (VDA 5050 orders).

* `elements` — [`RouteNode`][speedplan.route.RouteNode] and `RouteEdge`, each with its limits;
* `route` — [`Route`][speedplan.Route]: the released base's length, node positions ``node_s``,
  edge spans, stops and stop-to-stop legs;
* `profile` — [`RouteProfile`][speedplan.RouteProfile] (what `speedplan.plan_route`
  returns: the legs' profiles and the turns on the spot between them, stitched; node arrival
  and leave times), [`RouteTurn`][speedplan.route.RouteTurn] and `RouteTrajectory`;
* `vda5050` — reading VDA 5050 2.0, 2.1 and 3.0 orders into nodes and edges
  ([`Route.from_vda5050`][speedplan.Route.from_vda5050]), trajectories included.

This layer sits between ``timing`` and the top level; it imports ``core``, ``geometry`` and
``timing``.
"""

from .profile import RouteProfile, RouteTrajectory, RouteTurn
from .route import HEADING_TOLERANCE, THETA_TOLERANCE, Route, RouteEdge, RouteNode

__all__ = ["HEADING_TOLERANCE", "THETA_TOLERANCE", "Route", "RouteEdge", "RouteNode",
           "RouteProfile", "RouteTrajectory", "RouteTurn"]

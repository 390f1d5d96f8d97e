"""Geometry: arc-length parametrised paths, their constructors and speed bounds.

Modules, one job each:

* `path` — [`Path`][speedplan.Path] (immutable chain of pieces, vectorised
  ``point``/``heading``/``curvature``/``direction`` over ``s``, cusps where the direction of
  travel flips) and `PathSamples`;
* `primitives` — [`Line`][speedplan.geometry.Line], [`Arc`][speedplan.geometry.Arc], `Clothoid` and
  their exact evaluation;
* `pieces` — the piece interface and arc-length reparametrisation of
  parametric curves;
* `corners` — waypoints to straight legs with G2
  clothoid–arc–clothoid corners and cusps (the default);
* `fitting` — the waypoint kinds (G2 corners, G1 clothoid chain,
  spline, rounded polyline) and their options;
* `nurbs` — NURBS (VDA 5050 ``trajectory``);
* `bounds` — [`speed_bounds`][speedplan.speed_bounds] ``mu+(s)``, `SpeedBound`,
  [`SpeedZone`][speedplan.SpeedZone], [`SpanLimit`][speedplan.SpanLimit], `zone_intervals`,
  `bound_breakpoints`, `CellSamples`.

This layer imports only from `speedplan.core`.
"""

from .bounds import (
    CellSamples,
    SpanLimit,
    SpeedBound,
    SpeedZone,
    bound_breakpoints,
    speed_bounds,
    zone_intervals,
)
from .path import Arc, Clothoid, Line, Path, PathSamples

__all__ = [
    "Arc",
    "CellSamples",
    "Clothoid",
    "Line",
    "Path",
    "PathSamples",
    "SpanLimit",
    "SpeedBound",
    "SpeedZone",
    "bound_breakpoints",
    "speed_bounds",
    "zone_intervals",
]

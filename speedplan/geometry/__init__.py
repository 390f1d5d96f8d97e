"""Geometry: arc-length parametrised paths, their constructors and speed bounds.

Modules, one job each:

* :mod:`~speedplan.geometry.path` — :class:`Path` (immutable chain of pieces, vectorised
  ``point``/``heading``/``curvature``/``direction`` over ``s``, cusps where the direction of
  travel flips) and :class:`PathSamples`;
* :mod:`~speedplan.geometry.primitives` — :class:`Line`, :class:`Arc`, :class:`Clothoid` and
  their exact evaluation;
* :mod:`~speedplan.geometry.pieces` — the piece interface and arc-length reparametrisation of
  parametric curves;
* :mod:`~speedplan.geometry.corners` — waypoints to straight legs with G2
  clothoid–arc–clothoid corners and cusps (the default);
* :mod:`~speedplan.geometry.fitting` — the waypoint kinds (G2 corners, G1 clothoid chain,
  spline, rounded polyline) and their options;
* :mod:`~speedplan.geometry.nurbs` — NURBS (VDA 5050 ``trajectory``);
* :mod:`~speedplan.geometry.bounds` — :func:`speed_bounds` ``mu+(s)``, :class:`SpeedBound`,
  :class:`SpeedZone`, :class:`SpanLimit`, :func:`zone_intervals`,
  :func:`bound_breakpoints`.

This layer imports only ``errors``, ``_checks`` and ``limits``.
"""

from .bounds import (
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

"""G2 corner paths: straight legs joined by clothoid–arc–clothoid corners, and cusps.

The layout standard of AGV guide paths and roads. Each corner of the waypoint polyline is
replaced by a clothoid from the incoming leg (curvature 0 → ``1/R``), a circular arc of radius
``R`` and a mirrored clothoid onto the outgoing leg (``1/R`` → 0), symmetric about the
corner's bisector. The curvature is continuous everywhere and 0 on the legs and at both ends
of each corner, so lateral acceleration never steps and lateral jerk stays bounded.

Shape and size of a corner turning by ``α``:

* ``transition`` (``f``, default `DEFAULT_TRANSITION`) is the share of ``α`` turned in
  the two clothoids (each turns ``f α / 2``), the rest in the arc; ``f = 1`` is a symmetric
  clothoid pair without arc. It fixes the corner's *shape*; every length of the corner is then
  proportional to ``R`` (scale-free: the same corner in millimetres or kilometres).
* ``R`` is the largest radius such that the corner stays within ``max_deviation`` of the
  waypoint (its midpoint, the nearest point to the waypoint, is at distance ``R · g(α, f)``)
  and the corner fits its share of both legs (its tangent length, from the waypoint to where
  it leaves each leg, is ``R · t(α, f)``). The largest radius is the smallest curvature, what
  lets a vehicle drive the corner fastest.
* Leg sharing: a leg between two corners is split so that they never overlap: each corner may
  use half of it, or more when the other corner needs less than half (the unused room goes to
  the corner that wants it). The end legs belong to their only corner; the path starts and
  ends exactly at the first and last waypoints, along the legs, with curvature 0.

A waypoint where the next leg turns back by more than `CUSP_ANGLE` is a *cusp*: the
vehicle stops and drives the next part in reverse. For a turn ``α`` the vehicle's heading must
change by ``δ = α ∓ π`` (``|δ| < π - CUSP_ANGLE``): it drives on past the waypoint along a
corner turning by ``δ/2`` onto the bisector of the extended legs, stops at the cusp point
``Q`` (at most ``max_deviation`` beyond the waypoint) and reverses along the mirrored corner
onto the next leg. For a straight reversal (``δ = 0``) ``Q`` is the waypoint itself.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from ..core.checks import FloatArray, as_scalar
from ..core.errors import InvalidInputError
from ..core.numerics import wrap_angle
from .primitives import ClothoidPiece, PieceSpec, clothoid_chain, end_heading

__all__ = ["CUSP_ANGLE", "DEFAULT_DEVIATION", "DEFAULT_TRANSITION", "CornerShape",
           "as_deviation", "corner_shape", "find_reversal", "g2_chain", "g2_corners", "leg_turns"]

#: Default largest distance between a waypoint and the path [m] (``max_deviation``).
DEFAULT_DEVIATION = 0.25
#: Default share of a corner's turn taken by its two clothoids (``transition``).
#: 0.5: the radius is within 9 % of a plain arc's for every turn up to 150°, while the
#: sharpness (``dκ/ds``, what sets lateral jerk) is within 32 % of the clothoid pair's minimum;
#: smaller shares trade sharpness for radius quickly (docs/geometry.md).
DEFAULT_TRANSITION = 0.5
#: A waypoint where the path turns by more than this [rad] (150°) is a reversal (a cusp).
#: A corner of 150° within ``max_deviation`` ``d`` already has a radius of only ``0.32 d``
#: (0.08 m for the default, a crawl), and rounding it ever tighter towards 180° would send the
#: vehicle round a hairpin where the waypoints mean "back out".
CUSP_ANGLE = 5.0 * np.pi / 6.0
#: Turns below this [rad] are straight through: no corner.
_STRAIGHT = 1e-12


def as_deviation(value: Any) -> float:
    """``max_deviation`` [m]: > 0, ``inf`` allowed (corners as round as the legs allow)."""
    dev = as_scalar("max_deviation", value, nonnegative=True, allow_inf=True)
    if dev == 0.0:
        raise InvalidInputError(
            "`max_deviation`=0 keeps sharp corners, where the curvature is infinite and a "
            "vehicle must stop; pass max_deviation > 0, or split the path at the corners and "
            "plan each leg"
        )
    return dev


def leg_turns(pts: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Leg lengths [m], leg directions [rad] and the signed turn at each interior waypoint.

    Turns are wrapped into ``[-π, π)`` [rad], positive to the left; a straight reversal is
    ``-π``.
    """
    d = np.diff(pts, axis=0)
    legs = np.linalg.norm(d, axis=1)
    head = np.arctan2(d[:, 1], d[:, 0])
    return legs, head, wrap_angle(np.diff(head))


def find_reversal(pts: FloatArray) -> tuple[int, float] | None:
    """Row and signed turn [rad] of the first waypoint turning back by over ``CUSP_ANGLE``.

    ``None`` when there is none; only interior waypoints can turn.
    """
    _, _, turn = leg_turns(pts)
    rows = np.flatnonzero(np.abs(turn) > CUSP_ANGLE)
    if rows.size == 0:
        return None
    return int(rows[0]) + 1, float(turn[rows[0]])


@dataclass(frozen=True)
class CornerShape:
    """A symmetric clothoid–arc–clothoid corner of radius 1 turning by ``turn`` [rad].

    Attributes
    ----------
    turn : float
        Turn angle, > 0 [rad].
    transition : float
        Share of ``turn`` in the two clothoids.
    tangent : float
        Distance from the vertex to where the corner leaves each leg, per unit radius.
    deviation : float
        Distance from the vertex to the corner's midpoint, per unit radius.
    """

    turn: float
    transition: float
    tangent: float
    deviation: float

    @property
    def clothoid_length(self) -> float:
        """Length of each clothoid per unit radius: it turns ``transition · turn / 2``."""
        return self.transition * self.turn

    @property
    def arc_length(self) -> float:
        """Length of the arc per unit radius."""
        return (1.0 - self.transition) * self.turn


@lru_cache(maxsize=256)  # waypoint paths repeat their turns (a serpentine: 18 right angles)
def corner_shape(turn: float, transition: float) -> CornerShape:
    """The unit-radius corner turning by ``turn`` (> 0) [rad] with clothoid share ``transition``.

    The corner starts at the origin heading along +x and turns left; its midpoint ``M`` (end
    of the first clothoid and half the arc) has heading ``turn / 2``, so the vertex ``V`` on
    the x axis with ``VM`` along the symmetry axis is at ``M_x + M_y tan(turn/2)`` and
    ``|VM| = M_y / cos(turn/2)``. The pieces themselves compute ``M`` (to rounding).

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.geometry.corners import corner_shape
    >>> c = corner_shape(np.pi / 2, 1e-9)   # nearly a plain arc: R (1/cos 45° - 1), R tan 45°
    >>> round(c.deviation, 6), round(c.tangent, 6)
    (0.414214, 1.0)
    """
    lc = transition * turn
    spiral = ClothoidPiece((0.0, 0.0), 0.0, lc, 0.0, 1.0)
    end, theta = spiral.end
    half_arc = 0.5 * (1.0 - transition) * turn
    if half_arc > 0:
        end, _ = ClothoidPiece((float(end[0]), float(end[1])), theta, half_arc, 1.0, 1.0).end
    half = 0.5 * turn
    return CornerShape(turn, transition, float(end[0] + end[1] * np.tan(half)),
                       float(end[1] / np.cos(half)))


def _corner_pieces(
    start: FloatArray, theta: float, turn: float, radius: float, shape: CornerShape,
    direction: int,
) -> list[PieceSpec]:
    """Pieces of a corner from ``start`` with vehicle heading ``theta``, signed ``turn``.

    Each piece after the first starts where the previous one ends (``None``).
    """
    k = float(np.sign(turn)) / radius
    lc, la = shape.clothoid_length * radius, shape.arc_length * radius
    out: list[PieceSpec] = []
    point: tuple[float, float] | None = (float(start[0]), float(start[1]))
    heading = theta
    for length, k0, k1 in ((lc, 0.0, k), (la, k, k), (lc, k, 0.0)):
        if length > 0:
            out.append((point, heading, length, k0, k1, direction))
            heading, point = end_heading(heading, length, k0, k1), None
    return out


def _leg_room(legs: FloatArray, want: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Room [m] each waypoint's corner may take on the leg before and the leg after it.

    A leg between two corners: half of it each, or more where the other corner wants less
    than half. End legs belong to their only corner.
    """
    n = legs.size + 1
    before, after = np.zeros(n), np.zeros(n)
    for i, length in enumerate(legs):
        first, last = i == 0, i == legs.size - 1
        # Room for the corner at the leg's end (waypoint i + 1) and at its start (waypoint i).
        before[i + 1] = length if first else max(0.5 * length, length - want[i])
        after[i] = length if last else max(0.5 * length, length - want[i + 1])
    return before, after


def g2_corners(
    pts: FloatArray,
    max_deviation: float | None = None,
    transition: float | None = None,
) -> tuple[ClothoidPiece, ...]:
    """Straight legs joined by G2 clothoid–arc–clothoid corners; cusps where the path reverses.

    See the module docstring for the construction.

    Parameters
    ----------
    pts : ndarray, shape (n, 2)
        Checked waypoints [m].
    max_deviation : float, optional
        Largest distance from a waypoint to the path [m], > 0 (``inf``: as round as the legs
        allow); default `DEFAULT_DEVIATION`. At a cusp, the largest distance the vehicle
        drives beyond the waypoint.
    transition : float, optional
        Share of each corner's turn in its two clothoids, in ``(0, 1]``; default
        `DEFAULT_TRANSITION`.

    Returns
    -------
    tuple of ClothoidPiece
        Pieces after a cusp are driven in reverse (``direction = -1``) until the next one.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.geometry.corners import g2_corners
    >>> pieces = g2_corners(np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]]))
    >>> [(round(p.k0, 4), round(p.k1, 4)) for p in pieces]
    [(0.0, 0.0), (0.0, 1.8014), (1.8014, 1.8014), (1.8014, 0.0), (0.0, 0.0)]
    """
    dev = DEFAULT_DEVIATION if max_deviation is None else as_deviation(max_deviation)
    return g2_chain(pts, np.full(pts.shape[0], dev), transition)[0]


def g2_chain(
    pts: FloatArray, deviations: FloatArray, transition: float | None = None,
) -> tuple[tuple[ClothoidPiece, ...], FloatArray]:
    """`g2_corners` with one deviation per waypoint, and where each waypoint lies.

    Parameters
    ----------
    pts : ndarray, shape (n, 2)
        Checked waypoints [m].
    deviations : ndarray, shape (n,)
        Largest distance from each inner waypoint to the path [m] (> 0; the ends' values are
        not used). A route's nodes each have their own (VDA 5050 ``allowedDeviationXY``).
    transition : float, optional
        As in `g2_corners`.

    Returns
    -------
    pieces : tuple of ClothoidPiece
        As `g2_corners`.
    waypoint_s : ndarray, shape (n,)
        Arc length [m] of the path's point nearest to each waypoint: the midpoint of its
        corner (0 and the length at the ends; at a cusp, the cusp point).

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.geometry.corners import g2_chain
    >>> pts = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]])
    >>> pieces, at = g2_chain(pts, np.array([0.0, 0.5, 0.0]))
    >>> round(float(at[2] - sum(p.length for p in pieces)), 12), bool(at[1] < 10.0)
    (0.0, True)
    """
    dev = np.asarray(deviations, dtype=np.float64)
    share = DEFAULT_TRANSITION if transition is None else as_scalar(
        "transition", transition, positive=True)
    if share > 1.0:
        raise InvalidInputError(
            f"`transition` is the share of a corner's turn taken by its clothoids, in (0, 1]; "
            f"got {share!r}"
        )
    legs, head, turn = leg_turns(pts)
    n = pts.shape[0]
    cusp = np.zeros(n, dtype=bool)
    cusp[1:-1] = np.abs(turn) > CUSP_ANGLE
    # The angle each waypoint's corner turns: the turn, or at a cusp the half-turn δ/2 of the
    # vehicle's heading, δ = α ∓ π.
    bend = np.zeros(n)
    bend[1:-1] = np.where(cusp[1:-1], turn - np.pi * np.sign(turn), turn)
    bend[cusp] *= 0.5
    shapes: list[CornerShape | None] = [None] * n
    want = np.zeros(n)
    for i in range(1, n - 1):
        if abs(bend[i]) <= _STRAIGHT:
            continue
        shape = corner_shape(abs(float(bend[i])), share)
        shapes[i] = shape
        # A corner stays within `dev` of its waypoint; a cusp's corners within `dev` of it
        # too: their far end, the cusp point, is the tangent length beyond the waypoint.
        want[i] = dev[i] if cusp[i] else dev[i] * shape.tangent / shape.deviation
    before, after = _leg_room(legs, want)
    tangent = np.minimum(want, np.minimum(before, after))

    unit = np.diff(pts, axis=0) / legs[:, None]
    pieces: list[PieceSpec] = []  # built at the end in one pass (clothoid_chain)
    length = _RunningLength()
    waypoint_s = np.zeros(n)
    direction = 1
    theta = float(head[0])  # vehicle heading, unwrapped along the path
    for i in range(n - 1):
        # Each leg re-anchors the heading to its exact direction (nearest 2π branch), so
        # rounding in the corners never tilts a leg.
        facing = float(head[i]) + (0.0 if direction > 0 else np.pi)
        theta = facing + 2.0 * np.pi * round((theta - facing) / (2.0 * np.pi))
        t_out, t_in = float(tangent[i]), float(tangent[i + 1])
        straight = float(legs[i]) - t_out - t_in
        has_straight = straight > 1e-12 * legs[i]
        if has_straight:
            p = pts[i] + unit[i] * t_out
            pieces.append(((float(p[0]), float(p[1])), theta, straight, 0.0, 0.0, direction))
        if i == n - 2:
            break
        # The corner at waypoint i + 1; exactly at the first waypoint if it takes the leg.
        start = pts[i + 1] - unit[i] * t_in if i > 0 or has_straight else pts[0]
        corner, bent = shapes[i + 1], float(bend[i + 1])
        entry = length(pieces)
        if corner is not None:
            radius = t_in / corner.tangent
            pieces += _corner_pieces(start, theta, bent, radius, corner, direction)
        # The symmetric corner's middle; at a cusp its end, the cusp point.
        waypoint_s[i + 1] = length(pieces) if cusp[i + 1] else 0.5 * (entry + length(pieces))
        if not cusp[i + 1]:
            theta += bent
            continue
        # Cusp: stopped at Q on the bisector ray, t_in beyond the waypoint; the mirrored
        # corner then joins the next leg in the other direction (heading continuous).
        if corner is not None:
            q_dir = theta + bent + (0.0 if direction > 0 else np.pi)
            q = pts[i + 1] + t_in * np.array([np.cos(q_dir), np.sin(q_dir)])
            pieces += _corner_pieces(q, theta + bent, bent, radius, corner, -direction)
        theta += 2.0 * bent
        direction = -direction
    waypoint_s[-1] = length(pieces)
    return tuple(clothoid_chain(pieces)), waypoint_s


class _RunningLength:
    """``sum`` of the lengths of a growing list of pieces [m], adding only the new ones.

    The same additions in the same order as ``sum(...)`` over the whole list each time (so
    the same float), without the quadratic cost.
    """

    def __init__(self) -> None:
        self.count, self.total = 0, 0.0

    def __call__(self, pieces: list[PieceSpec]) -> float:
        for p in pieces[self.count:]:
            self.total += p[2]
        self.count = len(pieces)
        return float(self.total)

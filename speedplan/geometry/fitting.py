"""Paths through waypoints: G2 corners (default), G1 clothoid chain, spline, rounded polyline.

``"g2"`` lives in `corners`; this module dispatches on ``kind``,
validates the options of each kind and refuses reversals (turns back by more than
`CUSP_ANGLE`) in the kinds that cannot drive in reverse.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..core.checks import FloatArray, as_array, as_scalar, choice
from ..core.errors import InvalidInputError
from ..core.numerics import wrap_angle
from ._checks import check_waypoints
from .corners import CUSP_ANGLE, as_deviation, find_reversal, g2_corners, leg_turns
from .pieces import CurvePiece, Piece
from .primitives import ClothoidPiece

if TYPE_CHECKING:  # scipy.interpolate costs ~0.2 s to import: only kind="spline" needs it
    from scipy.interpolate import CubicSpline

__all__ = ["CORNER_FRACTION", "DEFAULT_KIND", "KINDS", "SplineCurve", "clothoid_chain",
           "estimate_headings", "fit_clothoid", "fit_waypoints", "rounded_polyline",
           "spline_piece"]

KINDS = ("g2", "clothoid", "spline", "polyline")
#: The kind of `Path.from_waypoints`, `Path.from_linestring`, CSV waypoints
#: without headings and [`speedplan.profile_from_waypoints`][speedplan.profile_from_waypoints].
DEFAULT_KIND = "g2"
#: The kinds each option applies to.
_OPTIONS = {"headings": ("clothoid",), "corner_radius": ("polyline",),
            "max_deviation": ("g2", "polyline"), "transition": ("g2",)}

#: Default polyline corner rounding: each arc starts this fraction of the shorter adjacent leg
#: before the corner (scale-free: the same path in millimetres or in metres).
CORNER_FRACTION = 0.25

# Composite Gauss–Legendre rule on [0, 1] (4 cells x 24 nodes) for the generalised Fresnel
# integrals of the G1 Hermite problem; the heading there varies by at most a few π.
_x, _w = np.polynomial.legendre.leggauss(24)
_T = ((np.arange(4)[:, None] + 0.5 * (_x[None, :] + 1.0)) / 4.0).ravel()
_TW = np.tile(_w / 8.0, 4)
del _x, _w

# Bertolazzi & Frego's fitted initial guess for A (their eq. 19 coefficients).
_CF = (2.989696028701907, 0.716228953608281, -0.458969738821509, -0.502821153340377,
       0.261062141752652, -0.045854475238709)


def fit_clothoid(p0: Any, theta0: float, p1: Any, theta1: float) -> ClothoidPiece:
    """The clothoid from pose ``(p0, theta0)`` to pose ``(p1, theta1)`` (G1 Hermite problem).

    Bertolazzi & Frego (2015): in the chord's frame the heading over ``t ∈ [0, 1]`` is
    ``θ(t) = φ0 + (δ - A) t + A t²`` with ``δ = φ1 - φ0``; ``A`` solves the generalised Fresnel
    equation ``∫₀¹ sin θ(t) dt = 0`` by Newton's method from their fitted guess, then
    ``L = |p1 - p0| / ∫₀¹ cos θ(t) dt``, ``k0 = (δ - A)/L`` and ``k1 = (δ + A)/L``.

    Parameters
    ----------
    p0, p1 : array_like, shape (2,)
        Start and end points [m], distinct.
    theta0, theta1 : float
        Start and end headings [rad]; the piece starts with exactly ``theta0`` and ends with
        ``theta1`` modulo 2π.

    Returns
    -------
    ClothoidPiece
        Exists for every pair of headings; when both point nearly back along the chord
        (``φ0 ≈ -φ1 ≈ ±π``) it is a long spiral (length unbounded as they reach ±π).

    Raises
    ------
    InvalidInputError
        Newton's iteration did not converge (not observed for headings in ``(-π, π)``).

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.geometry.fitting import fit_clothoid
    >>> c = fit_clothoid([0, 0], 0.0, [4, 2], np.pi / 2)
    >>> c.point(np.array(c.length)).round(10).tolist(), round(float(c.heading(c.length)), 12)
    ([4.0, 2.0], 1.570796326795)
    """
    a = np.asarray(p0, dtype=np.float64)
    d = np.asarray(p1, dtype=np.float64) - a
    r = float(np.hypot(d[0], d[1]))
    phi = float(np.arctan2(d[1], d[0]))
    phi0 = float(wrap_angle(theta0 - phi))
    phi1 = float(wrap_angle(theta1 - phi))
    if phi0 == 0.0 and phi1 == 0.0:  # collinear: a line, without quadrature rounding
        return ClothoidPiece((float(a[0]), float(a[1])), float(theta0), r, 0.0, 0.0)
    delta = phi1 - phi0
    X, Y = phi0 / np.pi, phi1 / np.pi
    xy = X * Y
    A = (phi0 + phi1) * (_CF[0] + xy * (_CF[1] + xy * _CF[2])
                         + (_CF[3] + xy * _CF[4]) * (X * X + Y * Y) + _CF[5] * (X**4 + Y**4))
    converged = False
    for _ in range(50):
        th = phi0 + (delta - A) * _T + A * _T * _T
        g = float(np.sin(th) @ _TW)
        dg = float(((_T * _T - _T) * np.cos(th)) @ _TW)
        if abs(g) <= 1e-15 or dg == 0.0:
            converged = abs(g) <= 1e-13
            break
        step = g / dg
        A -= step
        if abs(step) <= 1e-14 * max(1.0, abs(A)):
            converged = True
            break
    th = phi0 + (delta - A) * _T + A * _T * _T
    c = float(np.cos(th) @ _TW)
    if not converged or abs(float(np.sin(th) @ _TW)) > 1e-12 or not c > 1e-9:
        raise InvalidInputError(
            f"no clothoid joins ({a[0]:.6g}, {a[1]:.6g}) with heading {theta0:.6g} rad to "
            f"({a[0] + d[0]:.6g}, {a[1] + d[1]:.6g}) with heading {theta1:.6g} rad; change "
            "the `headings` or add an intermediate waypoint"
        )
    L = r / c
    return ClothoidPiece((float(a[0]), float(a[1])), float(theta0), L, (delta - A) / L,
                         (delta + A) / L)


def _chord_parameter(pts: FloatArray) -> FloatArray:
    return np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))))


def _is_closed(pts: FloatArray) -> bool:
    """Whether the last waypoint repeats the first (to ``1e-12`` of the polyline's length)."""
    total = float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1)))
    return pts.shape[0] > 2 and bool(np.allclose(pts[0], pts[-1], rtol=0.0, atol=1e-12 * total))


def _chord_spline(pts: FloatArray) -> CubicSpline:
    """Chord-length cubic spline: periodic for closed point sets, not-a-knot otherwise."""
    from scipy.interpolate import CubicSpline

    tau = _chord_parameter(pts)
    if pts.shape[0] == 2:
        return CubicSpline(tau, pts, bc_type="natural")
    closed = _is_closed(pts)
    if closed:
        pts = pts.copy()
        pts[-1] = pts[0]  # periodic splines need exactly equal ends
    return CubicSpline(tau, pts, bc_type="periodic" if closed else "not-a-knot")


def estimate_headings(pts: FloatArray) -> FloatArray:
    """Waypoint headings for a clothoid chain: the leg bisectors, the legs' at the ends [rad].

    At an interior waypoint the heading halves the turn between the adjacent legs; at the
    first and last waypoint it is the leg's direction (for a closed point set, the bisector
    of the last and first legs). Unwrapped along the points. Measured against the former
    estimate (tangents of a chord-length cubic spline), the chain strays 2.4-4.6 times less
    from the legs (docs/geometry.md): the spline's end tangents swing off the first and last
    legs.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.geometry.fitting import estimate_headings
    >>> estimate_headings(np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]])).round(6).tolist()
    [0.0, 0.785398, 1.570796]
    """
    _, head, turn = leg_turns(pts)
    legs = head[0] + np.concatenate(([0.0], np.cumsum(turn)))  # unwrapped leg directions
    th = np.concatenate((legs[:1], legs[:-1] + 0.5 * turn, legs[-1:]))
    if _is_closed(pts):
        closing = float(wrap_angle(head[0] - head[-1]))
        th[0] -= 0.5 * closing
        th[-1] += 0.5 * closing
    out: FloatArray = th
    return out


def clothoid_chain(pts: FloatArray, headings: Any = None) -> tuple[ClothoidPiece, ...]:
    """One clothoid per leg through ``pts``, G1 at every waypoint.

    The headings at the waypoints are ``headings`` or, by default,
    `estimate_headings` (leg bisectors). Each leg solves the G1 Hermite problem
    (`fit_clothoid`); each leg starts with the previous leg's end heading, so the
    heading is continuous (not only modulo 2π).

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.geometry.fitting import clothoid_chain
    >>> chain = clothoid_chain(np.array([[0.0, 0.0], [5.0, 0.0], [10.0, 0.0]]))
    >>> [(round(c.length, 12), c.k0, c.k1) for c in chain]
    [(5.0, 0.0, 0.0), (5.0, 0.0, 0.0)]
    """
    n = pts.shape[0]
    if headings is None:
        th = estimate_headings(pts)
    else:
        th = as_array("headings", headings, ndim=1, length=n)
    pieces: list[ClothoidPiece] = []
    theta = float(th[0])
    for i in range(n - 1):
        piece = fit_clothoid(pts[i], theta, pts[i + 1], float(th[i + 1]))
        pieces.append(piece)
        theta = piece.end[1]
    return tuple(pieces)


@dataclass(frozen=True, eq=False)
class SplineCurve:
    """A `scipy.interpolate.CubicSpline` as a picklable parametric curve.

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.interpolate import CubicSpline
    >>> from speedplan.geometry.fitting import SplineCurve
    >>> c = SplineCurve(CubicSpline([0.0, 1.0], [[0.0, 0.0], [1.0, 1.0]]))
    >>> c(np.array([0.5]), 0).tolist(), c.breaks.tolist()
    ([[0.5, 0.5]], [0.0, 1.0])
    """

    spline: CubicSpline

    @property
    def breaks(self) -> FloatArray:
        """Knots of the spline."""
        out: FloatArray = np.asarray(self.spline.x, dtype=np.float64)
        return out

    def __call__(self, tau: FloatArray, nu: int) -> FloatArray:
        """``nu``-th derivative at parameters ``tau``, shape (m, 2)."""
        out: FloatArray = self.spline(np.asarray(tau, dtype=np.float64).ravel(), nu)
        return out


def spline_piece(pts: FloatArray) -> CurvePiece:
    """Chord-length cubic spline through ``pts``, reparametrised by arc length.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.geometry.fitting import spline_piece
    >>> round(spline_piece(np.array([[0.0, 0.0], [3.0, 4.0]])).length, 12)
    5.0
    """
    try:
        return CurvePiece(SplineCurve(_chord_spline(pts)))
    except InvalidInputError as exc:
        raise InvalidInputError(f"`xy`: {exc}") from exc


def rounded_polyline(
    pts: FloatArray,
    corner_radius: float | None = None,
    max_deviation: float | None = None,
) -> tuple[ClothoidPiece, ...]:
    """Straight legs joined by circular arcs tangent to both legs at every corner.

    Each corner's arc has the largest radius allowed by ``corner_radius`` and by
    ``max_deviation`` (distance from the corner to the arc's midpoint); with neither, the arc
    starts ``CORNER_FRACTION`` (a quarter) of the shorter adjacent leg before the corner. The
    tangent points never pass the middle of a leg, so the radius is reduced where legs are
    short. Why round by default: a corner of zero radius has infinite curvature, so the
    lateral-acceleration bound forces the vehicle to stop there; a scale-free default keeps
    the polyline drivable whatever the unit of length. Sharp corners (``0``) are rejected:
    split the path at the corners to plan a stop at each.

    Raises
    ------
    InvalidInputError
        The polyline turns back by more than 150° (a reversal, see `refuse_reversal`),
        or a rounding parameter is not > 0.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.geometry.fitting import rounded_polyline
    >>> legs = rounded_polyline(np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]]),
    ...                         max_deviation=0.5)
    >>> [round(p.length, 6) for p in legs], round(1 / legs[1].k0, 6)
    ([8.792893, 1.896119, 8.792893], 1.207107)
    """
    refuse_reversal(pts, "polyline")
    legs, head, turn = leg_turns(pts)
    unit = np.diff(pts, axis=0) / legs[:, None]
    half = 0.5 * np.abs(turn)
    shorter = np.minimum(legs[:-1], legs[1:])
    with np.errstate(divide="ignore", invalid="ignore"):
        tangent = np.full(turn.shape, np.inf)
        if corner_radius is not None:
            radius = as_scalar("corner_radius", corner_radius, positive=True)
            tangent = np.minimum(tangent, radius * np.tan(half))
        if max_deviation is not None:
            dev = as_deviation(max_deviation)
            # Corner-to-arc distance d = R (1/cos(α/2) - 1), tangent length R tan(α/2).
            tangent = np.minimum(tangent, dev * np.sin(half) / (1.0 - np.cos(half)))
        if corner_radius is None and max_deviation is None:
            tangent = CORNER_FRACTION * shorter
    tangent = np.where(np.abs(turn) < 1e-12, 0.0, np.minimum(tangent, 0.5 * shorter))
    heading = head[0] + np.concatenate(([0.0], np.cumsum(turn)))  # continuous, not wrapped
    before = np.concatenate(([0.0], tangent))
    after = np.concatenate((tangent, [0.0]))
    pieces: list[ClothoidPiece] = []
    for i in range(legs.size):
        straight = legs[i] - before[i] - after[i]
        if straight > 1e-12 * legs[i]:
            p = pts[i] + unit[i] * before[i]
            pieces.append(ClothoidPiece((float(p[0]), float(p[1])), float(heading[i]),
                                        float(straight), 0.0, 0.0))
        if i < turn.size and tangent[i] > 0:
            radius_i = tangent[i] / np.tan(half[i])
            p = pts[i + 1] - unit[i] * tangent[i]
            k = float(np.sign(turn[i]) / radius_i)
            pieces.append(ClothoidPiece((float(p[0]), float(p[1])), float(heading[i]),
                                        float(radius_i * abs(turn[i])), k, k))
    return tuple(pieces)


def refuse_reversal(pts: FloatArray, kind: str, name: str = "xy") -> None:
    """Raise if the waypoints turn back by more than ``CUSP_ANGLE`` (150°) somewhere.

    Only ``kind="g2"`` can drive a reversal (a cusp); the other kinds would loop round it
    or fold onto themselves.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.geometry.fitting import refuse_reversal
    >>> from speedplan import InvalidInputError
    >>> try:
    ...     refuse_reversal(np.array([[0.0, 0.0], [4.0, 0.0], [1.0, 0.2]]), "clothoid")
    ... except InvalidInputError as exc:
    ...     print(str(exc)[:65])
    `xy` reverses direction at row 1 (turns back by 176.2°, more than
    """
    found = find_reversal(pts)
    if found is None:
        return
    row, turn = found
    raise InvalidInputError(
        f"`{name}` reverses direction at row {row} (turns back by {np.degrees(abs(turn)):.1f}°, "
        f"more than {np.degrees(CUSP_ANGLE):.0f}°: a cusp); kind={kind!r} cannot drive in "
        "reverse — use kind='g2' (the default), which stops there and reverses, or split the "
        "path there"
    )


def fit_waypoints(
    xy: Any,
    kind: str = DEFAULT_KIND,
    *,
    headings: Any = None,
    corner_radius: float | None = None,
    max_deviation: float | None = None,
    transition: float | None = None,
    name: str = "xy",
) -> tuple[Piece, ...]:
    """Pieces of a path through the waypoints ``xy``; see `Path.from_waypoints`.

    ``name`` is the argument name used in error messages.

    Examples
    --------
    >>> from speedplan.geometry.fitting import fit_waypoints
    >>> len(fit_waypoints([[0, 0], [4, 0], [4, 4]], "polyline"))
    3
    >>> len(fit_waypoints([[0, 0], [4, 0], [4, 4]]))  # line, clothoid, arc, clothoid, line
    5
    """
    choice("kind", kind, KINDS)
    pts = check_waypoints(xy, name)
    given = {"headings": headings, "corner_radius": corner_radius,
             "max_deviation": max_deviation, "transition": transition}
    for option, value in given.items():
        applies = _OPTIONS[option]
        if value is not None and kind not in applies:
            listed = " and ".join(f"kind={k!r}" for k in applies)
            raise InvalidInputError(
                f"`{option}` applies to {listed} only; got kind={kind!r} — pass "
                f"kind={applies[0]!r} to use it"
            )
    if kind == "g2":
        return g2_corners(pts, max_deviation, transition)
    refuse_reversal(pts, kind, name)
    if kind == "clothoid":
        return clothoid_chain(pts, headings)
    if kind == "spline":
        return (spline_piece(pts),)
    return rounded_polyline(pts, corner_radius, max_deviation)

"""Line, arc and clothoid segments, and the piece that evaluates them exactly.

Every segment and piece may be driven in reverse (``reverse=True`` / ``direction=-1``): the
vehicle's heading ``θ`` is then opposite to its direction of travel, which is
``direction · (cos θ, sin θ)``; the curvature is that of the curve traversed in the direction
of travel, and the heading changes at the rate of the curvature in both directions.

A clothoid has curvature linear in arc length, so its heading is quadratic and its position
is ``∫ (cos θ, sin θ)``, a (generalised) Fresnel integral. `ClothoidPiece` evaluates it
by Gauss–Legendre quadrature on cells over which the heading turns by at most 0.25 rad: 16
nodes integrate ``cos``/``sin`` of a quadratic over such a cell to rounding, for any
curvature and sharpness (no separate ``k1 ≈ k0`` branch is needed, unlike the Fresnel-function
formula). Arcs and lines are the constant-curvature cases of the same piece. A
[`Path`][speedplan.Path] made only of such pieces evaluates all its positions in
one pass instead: from the same tabulated cell starts, the step by the power series of
`turn_integral` (equal to the quadrature to rounding, no cosine per node).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..core.checks import FloatArray, IntArray, as_scalar
from ..core.errors import InvalidInputError
from ._checks import as_direction, as_reverse
from .pieces import GAUSS_NODES, GAUSS_WEIGHTS, Piece

__all__ = ["Arc", "Clothoid", "ClothoidPiece", "Line", "PieceSpec", "Segment", "as_segment",
           "clothoid_chain", "end_heading", "segment_piece", "segment_spec", "turn_integral"]

#: Largest heading change over one quadrature cell of a clothoid [rad].
_CELL_TURN = 0.25
_EMPTY = np.empty(0)


def _set_checked(segment: Any, **checks: Callable[[str, Any], Any]) -> None:
    """Replace each named field of the frozen ``segment`` by ``check(name, value)``, in order."""
    for name, check in checks.items():
        object.__setattr__(segment, name, check(name, getattr(segment, name)))


def _positive(name: str, value: Any) -> float:
    return as_scalar(name, value, positive=True)


def _turn(name: str, value: Any) -> float:
    """An arc's angle: a non-zero number [rad]."""
    angle = as_scalar(name, value)
    if angle == 0.0:
        raise InvalidInputError("`angle` of an Arc must be non-zero; use a Line instead")
    return angle


@dataclass(frozen=True)
class Line:
    """Straight segment.

    Parameters
    ----------
    length : float
        Length [m], > 0.
    reverse : bool
        Driven in reverse (default ``False``): the vehicle moves opposite to its heading.

    Examples
    --------
    >>> from speedplan.geometry import Line, Path
    >>> Path.from_segments([Line(3.0)]).point(3.0).tolist()
    [3.0, 0.0]
    >>> Path.from_segments([Line(3.0), Line(1.0, reverse=True)]).point(4.0).tolist()
    [2.0, 0.0]
    """

    length: float
    reverse: bool = False

    def __post_init__(self) -> None:
        _set_checked(self, length=_positive, reverse=as_reverse)


@dataclass(frozen=True)
class Arc:
    """Circular arc: positive ``radius``, signed ``angle`` (positive turns left).

    Parameters
    ----------
    radius : float
        Radius [m], > 0; the arc is ``radius * |angle|`` long.
    angle : float
        Angle turned [rad], non-zero; its sign gives the direction (left positive) and the
        curvature is ``sign(angle) / radius``.
    reverse : bool
        Driven in reverse (default ``False``); the curvature is that of the arc traversed in
        the direction of travel and the vehicle's heading still changes by ``angle``.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.geometry import Arc, Path
    >>> p = Path.from_segments([Arc(radius=2.0, angle=-np.pi / 2)])
    >>> round(p.length, 12), float(p.curvature(1.0)), p.point(p.length).round(12).tolist()
    (3.14159265359, -0.5, [2.0, -2.0])
    """

    radius: float
    angle: float
    reverse: bool = False

    def __post_init__(self) -> None:
        _set_checked(self, radius=_positive, angle=_turn, reverse=as_reverse)


@dataclass(frozen=True)
class Clothoid:
    """Clothoid (Euler spiral): curvature linear in arc length from ``k0`` to ``k1``.

    Parameters
    ----------
    length : float
        Arc length [m], > 0.
    k0, k1 : float
        Signed curvature at the start and at the end [1/m] (positive: turning left), of the
        curve traversed in the direction of travel.
    reverse : bool
        Driven in reverse (default ``False``).

    Examples
    --------
    >>> from speedplan.geometry import Clothoid, Path
    >>> p = Path.from_segments([Clothoid(length=2.0, k0=0.0, k1=0.5)])
    >>> p.curvature([0.0, 1.0, 2.0]).tolist(), float(p.heading(2.0))
    ([0.0, 0.25, 0.5], 0.5)
    """

    length: float
    k0: float
    k1: float
    reverse: bool = False

    def __post_init__(self) -> None:
        _set_checked(self, length=_positive, k0=as_scalar, k1=as_scalar, reverse=as_reverse)


Segment = Line | Arc | Clothoid

_FIELDS: dict[str, tuple[type[Line | Arc | Clothoid], tuple[str, ...]]] = {
    "line": (Line, ("length",)),
    "arc": (Arc, ("radius", "angle")),
    "clothoid": (Clothoid, ("length", "k0", "k1")),
}


def as_segment(seg: Any, name: str) -> Segment:
    """A [`Line`][speedplan.geometry.Line], `Arc` or `Clothoid` from itself or from a dict.

    Dicts carry ``"type"`` (``"line"``, ``"arc"`` or ``"clothoid"``), the fields of that
    class and optionally ``"reverse"`` (``true`` for a piece driven in reverse). Errors name
    the argument, e.g. ``segments[2].radius``.
    """
    if isinstance(seg, Line | Arc | Clothoid):
        return seg
    if not isinstance(seg, Mapping):
        raise InvalidInputError(
            f"`{name}` must be a Line, Arc, Clothoid or a dict with a 'type'; got {seg!r}"
        )
    kind = seg.get("type")
    if kind not in _FIELDS:
        raise InvalidInputError(
            f"`{name}` has type {kind!r}; use 'line', 'arc' or 'clothoid'"
        )
    cls, names = _FIELDS[kind]
    missing = [f for f in names if f not in seg]
    if missing:
        raise InvalidInputError(f"`{name}` ({kind}) lacks the field(s) {missing}")
    unknown = sorted(set(seg) - set(names) - {"type", "reverse"})
    if unknown:
        raise InvalidInputError(f"`{name}` ({kind}) has unknown field(s) {unknown}")
    fields: dict[str, Any] = {f: seg[f] for f in names}
    fields["reverse"] = seg.get("reverse", False)
    try:
        return cls(**fields)
    except InvalidInputError as exc:
        # Prefix the field name with the segment's position: `length` -> `segments[0].length`.
        raise InvalidInputError(str(exc).replace("`", f"`{name}.", 1)) from exc


@dataclass(frozen=True, eq=False)
class ClothoidPiece(Piece):
    """Curvature ``k0 + (k1 - k0) u / length`` from ``start`` with (vehicle) heading ``theta0``.

    ``direction = -1`` drives it in reverse: the travel tangent is ``direction · (cos θ,
    sin θ)``. Positions are tabulated at cell boundaries (heading turn <= 0.25 rad per cell);
    a query adds a 16-point Gauss–Legendre integral from its cell's start, accurate to
    rounding (a [`Path`][speedplan.Path] of such pieces adds
    `turn_integral` from the same cell starts instead, in one pass over all pieces).
    """

    start: tuple[float, float]
    theta0: float
    length: float
    k0: float
    k1: float
    direction: int = 1
    _knots: FloatArray = field(init=False, repr=False)
    _knot_xy: FloatArray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "direction", as_direction("direction", self.direction))
        ((knots, steps),) = _tabulate(np.array([self.theta0]), np.array([self.length]),
                                      np.array([self.k0]), np.array([self.k1]),
                                      np.array([float(self.direction)]))
        object.__setattr__(self, "_knots", knots)
        object.__setattr__(self, "_knot_xy", np.asarray(self.start, dtype=np.float64) + steps)

    @property
    def end(self) -> tuple[FloatArray, float]:
        """End point [m] and end (vehicle) heading [rad]."""
        return self._knot_xy[-1].copy(), float(self.heading(np.array(self.length)))

    def heading(self, u: FloatArray) -> FloatArray:
        """Vehicle heading ``θ0 + k0 u + (k1 - k0) u² / (2 length)`` [rad]."""
        u = np.asarray(u, dtype=np.float64)
        sharpness = (self.k1 - self.k0) / self.length
        out: FloatArray = self.theta0 + u * (self.k0 + 0.5 * sharpness * u)
        return out

    def curvature(self, u: FloatArray) -> FloatArray:
        """Curvature, linear from ``k0`` to ``k1`` [1/m]."""
        u = np.asarray(u, dtype=np.float64)
        out: FloatArray = self.k0 + (self.k1 - self.k0) * (u / self.length)
        return out

    def curvature_rate(self, u: FloatArray) -> FloatArray:
        """The sharpness ``(k1 - k0) / length`` [1/m²], constant along the piece."""
        return np.full(np.shape(u), (self.k1 - self.k0) / self.length)

    @property
    def straight(self) -> bool:
        """Whether the piece is a line (``k0 = k1 = 0``)."""
        return self.k0 == 0.0 and self.k1 == 0.0

    def _integrate(self, a: FloatArray, b: FloatArray) -> FloatArray:
        """Displacements from ``a`` to ``b`` (direction of travel included)."""
        width = (b - a)[:, None] * self.direction
        th = self.heading(a[:, None] + (b - a)[:, None] * GAUSS_NODES[None, :])
        return np.column_stack(((np.cos(th) * width) @ GAUSS_WEIGHTS,
                                (np.sin(th) * width) @ GAUSS_WEIGHTS))

    def point(self, u: FloatArray) -> FloatArray:
        """Positions: the cell start's position plus a quadrature from it [m]."""
        u = np.clip(np.asarray(u, dtype=np.float64), 0.0, self.length)
        if self.k0 == 0.0 and self.k1 == 0.0:  # a line: exact, no quadrature rounding
            direction = self.direction * np.array([np.cos(self.theta0), np.sin(self.theta0)])
            line: FloatArray = np.asarray(self.start) + u[..., None] * direction
            return line
        flat = u.ravel()
        j = np.clip(np.searchsorted(self._knots, flat, side="right") - 1, 0, self._knots.size - 2)
        out = self._knot_xy[j] + self._integrate(self._knots[j], flat)
        return out.reshape(*u.shape, 2)

    def reversed(self, swap_direction: bool = False) -> ClothoidPiece:
        """The same clothoid from its end, curvature from ``-k1`` to ``-k0``.

        Heading + π and the same direction flag by default; with ``swap_direction`` the
        heading is kept and the direction flag flipped (see `Piece.reversed`).
        """
        end, theta = self.end
        turn = 0.0 if swap_direction else np.pi
        return ClothoidPiece((float(end[0]), float(end[1])), theta + turn, self.length,
                             -self.k1, -self.k0,
                             -self.direction if swap_direction else self.direction)


def _cells(turn: FloatArray) -> IntArray:
    """Quadrature cells of pieces whose heading turns by at most ``turn`` [rad]."""
    return np.clip(np.ceil(turn / _CELL_TURN), 1, 1_000_000).astype(np.intp)


def _tabulate(theta0: FloatArray, length: FloatArray, k0: FloatArray, k1: FloatArray,
              direction: FloatArray) -> list[tuple[FloatArray, FloatArray]]:
    """Knots and knot positions relative to the start (first row 0) of clothoid pieces [m].

    One vectorised pass for all pieces with the same number of cells (what keeps building a
    path of 70 pieces cheap); per piece the arithmetic of `ClothoidPiece._integrate`,
    knots as ``np.linspace(0, length, m + 1)`` and a running sum of the cell steps.
    """
    counts = _cells(np.maximum(np.abs(k0), np.abs(k1)) * length)
    out: list[tuple[FloatArray, FloatArray]] = [(_EMPTY, _EMPTY)] * length.size
    for m in np.unique(counts).tolist():
        rows = np.flatnonzero(counts == m)
        size = length[rows, None]
        knots = np.arange(m + 1) * (size / m)  # what np.linspace computes
        knots[:, -1] = size[:, 0]
        a, width = knots[:, :-1], np.diff(knots, axis=1)
        sharpness = ((k1[rows] - k0[rows]) / length[rows])[:, None, None]
        u = a[..., None] + width[..., None] * GAUSS_NODES
        th = theta0[rows, None, None] + u * (k0[rows, None, None] + 0.5 * sharpness * u)
        scaled = width * direction[rows, None]
        steps = np.empty((rows.size, m + 1, 2))
        steps[:, 0] = 0.0
        steps[:, 1:, 0] = (np.cos(th) * scaled[..., None]) @ GAUSS_WEIGHTS
        steps[:, 1:, 1] = (np.sin(th) * scaled[..., None]) @ GAUSS_WEIGHTS
        np.cumsum(steps, axis=1, out=steps)
        for r, row in enumerate(rows.tolist()):
            out[row] = (knots[r], steps[r])
    return out


#: A piece's description for `clothoid_chain`: start point (``None``: where the
#: previous piece ends), vehicle heading [rad], length [m], curvatures k0, k1 [1/m], direction.
PieceSpec = tuple[tuple[float, float] | None, float, float, float, float, int]


def end_heading(theta0: float, length: float, k0: float, k1: float) -> float:
    """Heading at the end of a clothoid piece [rad], as `ClothoidPiece.end` gives it."""
    return theta0 + length * (k0 + 0.5 * ((k1 - k0) / length) * length)


_PIECE_FIELDS = ("start", "theta0", "length", "k0", "k1", "direction", "_knots", "_knot_xy")


def clothoid_chain(specs: list[PieceSpec]) -> list[ClothoidPiece]:
    """The pieces of ``specs``, tabulated in one vectorised pass.

    The same pieces as ``ClothoidPiece(start, theta0, length, k0, k1, direction)`` one by
    one, a start of ``None`` being the previous piece's end point.
    """
    if not specs:
        return []
    theta0, length, k0, k1, direction = (np.array([s[i] for s in specs], dtype=np.float64)
                                         for i in range(1, 6))
    pieces: list[ClothoidPiece] = []
    start: tuple[float, float] | None = None
    for spec, (knots, steps) in zip(specs, _tabulate(theta0, length, k0, k1, direction),
                                    strict=True):
        if spec[0] is not None:
            start = spec[0]
        assert start is not None
        xy = np.asarray(start, dtype=np.float64) + steps
        piece = ClothoidPiece.__new__(ClothoidPiece)
        # The fields a frozen dataclass's __init__ would set, in one update of its __dict__.
        vars(piece).update(zip(_PIECE_FIELDS, (
            start, *spec[1:5], as_direction("direction", spec[5]), knots, xy), strict=True))
        pieces.append(piece)
        start = (float(xy[-1, 0]), float(xy[-1, 1]))
    return pieces


def turn_integral(a: FloatArray, b: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``∫₀¹ exp(i (a x + b x²/2)) dx`` (real and imaginary parts), by its power series.

    The position of a clothoid a step ``h`` from a point of heading ``θ`` and curvature ``κ``
    is ``h · exp(i θ) ·`` this integral with ``a = κ h`` and ``b = (dκ/ds) h²``. The integrand
    ``z`` solves ``z' = i (a + b x) z``, so its Taylor coefficients follow
    ``(n + 1) c[n+1] = i (a c[n] + b c[n-1])``; for a step within one quadrature cell
    (``|a|, |a + b| <= 0.25``) they fall below ``1e-17`` after 12-20 terms and the sum is
    exact to rounding, with no transcendental function at all: several times faster than a
    16-point Gauss–Legendre rule (32 cosines and sines per point). The number of terms is
    that of a bound (the recurrence on ``max |a|``, ``max |b|``), the same for every point.
    Meant for ``|a|, |b| <= 1``; larger arguments raise ``ValueError``.
    """
    amax = float(np.max(np.abs(a), initial=0.0))
    bmax = float(np.max(np.abs(b), initial=0.0))
    if amax > 1.0 or bmax > 1.0:
        raise ValueError("turn_integral is for steps turning by at most 1 rad")
    terms, bound, before = 0, 1.0, 0.0
    while bound + before > 1e-17 and terms < 60:
        bound, before = (amax * bound + bmax * before) / (terms + 1), bound
        terms += 1
    re, im = np.ones_like(a), np.zeros_like(a)
    re_prev, im_prev = np.zeros_like(a), np.zeros_like(a)
    sum_re, sum_im = re.copy(), im.copy()
    tmp = np.empty_like(a)  # in place: the loop is ~12 array operations a term
    for n in range(1, terms + 1):
        # c[n] = i (a c[n-1] + b c[n-2]) / n; multiplying by i maps (re, im) to (-im, re).
        re_next = a * im
        np.multiply(b, im_prev, out=tmp)
        re_next += tmp
        re_next *= -1.0 / n
        im_next = a * re
        np.multiply(b, re_prev, out=tmp)
        im_next += tmp
        im_next *= 1.0 / n
        re_prev, im_prev, re, im = re, im, re_next, im_next
        np.multiply(re, 1.0 / (n + 1), out=tmp)
        sum_re += tmp
        np.multiply(im, 1.0 / (n + 1), out=tmp)
        sum_im += tmp
    return sum_re, sum_im


def segment_spec(seg: Segment, start: tuple[float, float] | None, theta0: float) -> PieceSpec:
    """The `PieceSpec` of ``seg`` from ``start`` with vehicle heading ``theta0`` [rad]."""
    d = -1 if seg.reverse else 1
    if isinstance(seg, Line):
        return (start, theta0, seg.length, 0.0, 0.0, d)
    if isinstance(seg, Arc):
        k = float(np.sign(seg.angle)) / seg.radius
        return (start, theta0, seg.radius * abs(seg.angle), k, k, d)
    return (start, theta0, seg.length, seg.k0, seg.k1, d)


def segment_piece(seg: Segment, start: tuple[float, float], theta0: float) -> ClothoidPiece:
    """The piece of ``seg`` starting at ``start`` with vehicle heading ``theta0`` [rad]."""
    _, theta0, length, k0, k1, d = segment_spec(seg, start, theta0)
    return ClothoidPiece(start, theta0, length, k0, k1, d)

"""NURBS curves as in a VDA 5050 edge ``trajectory`` (degree, knotVector, controlPoints)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..core.checks import FloatArray, as_array
from ..core.errors import InvalidInputError
from ._checks import as_int
from .pieces import CurvePiece

if TYPE_CHECKING:  # scipy.interpolate costs ~0.2 s to import: only NURBS edges need it
    from scipy.interpolate import BSpline

__all__ = ["NurbsCurve", "nurbs_piece", "straight_chord"]

#: Positions closer than this fraction of the control polygon's extent count as equal (end
#: points against control points, the two sides of a repeated knot).
_POSITION_TOLERANCE = 1e-9


@dataclass(frozen=True, eq=False)
class NurbsCurve:
    """A rational B-spline ``r(τ) = P(τ) / W(τ)`` as a picklable parametric curve.

    ``P`` and ``W`` are the B-splines of the homogeneous control points ``(w x, w y)`` and of
    the weights ``w`` (one `scipy.interpolate.BSpline` with three columns); derivatives
    follow from the quotient rule.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.geometry.nurbs import NurbsCurve
    >>> c = NurbsCurve(1, np.array([0, 0, 1, 1.0]), np.array([[0, 0], [2, 2.0]]), np.ones(2))
    >>> c(np.array([0.5]), 0).tolist(), c(np.array([0.5]), 1).tolist()
    ([[1.0, 1.0]], [[2.0, 2.0]])
    """

    degree: int
    knots: FloatArray
    control_points: FloatArray
    weights: FloatArray
    _spline: BSpline = field(init=False, repr=False)

    def __post_init__(self) -> None:
        from scipy.interpolate import BSpline

        homog = np.column_stack((self.control_points * self.weights[:, None], self.weights))
        object.__setattr__(self, "_spline", BSpline(self.knots, homog, self.degree))

    def _homogeneous(self, tau: FloatArray, nu: int) -> FloatArray:
        # Derivatives of the local polynomial piece: fine at repeated knots, where
        # BSpline.derivative() refuses (the curve is smooth there when its heading is).
        if nu > self.degree:
            return np.zeros((tau.size, 3))
        out: FloatArray = self._spline(tau, nu)
        return out

    @property
    def domain(self) -> tuple[float, float]:
        """Parameter range ``[t_degree, t_m]`` where the basis sums to one."""
        m = self.control_points.shape[0]
        return float(self.knots[self.degree]), float(self.knots[m])

    @property
    def breaks(self) -> FloatArray:
        """Distinct knots inside the domain."""
        lo, hi = self.domain
        t = np.unique(self.knots)
        out: FloatArray = t[(t >= lo) & (t <= hi)]
        return out

    def derivatives(self, tau: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``r, r', r''`` at ``tau`` from one evaluation of each homogeneous derivative.

        The same numbers as ``self(tau, 0)``, ``self(tau, 1)``, ``self(tau, 2)`` with half the
        B-spline evaluations (each call costs tens of µs besides its points).
        """
        lo, hi = self.domain
        tau = np.clip(np.asarray(tau, dtype=np.float64).ravel(), lo, hi)
        h0, h1, h2 = (self._homogeneous(tau, nu) for nu in (0, 1, 2))
        wt = h0[:, 2:3]
        r = h0[:, :2] / wt
        r1 = (h1[:, :2] - r * h1[:, 2:3]) / wt
        r2 = (h2[:, :2] - 2.0 * r1 * h1[:, 2:3] - r * h2[:, 2:3]) / wt
        return r, r1, r2

    def __call__(self, tau: FloatArray, nu: int) -> FloatArray:
        """``nu``-th derivative (0, 1 or 2) at parameters ``tau`` (clipped to the domain)."""
        lo, hi = self.domain
        tau = np.clip(np.asarray(tau, dtype=np.float64).ravel(), lo, hi)
        h0 = self._homogeneous(tau, 0)
        wt = h0[:, 2:3]
        r = h0[:, :2] / wt
        if nu == 0:
            return np.asarray(r, dtype=np.float64)
        h1 = self._homogeneous(tau, 1)
        r1 = (h1[:, :2] - r * h1[:, 2:3]) / wt
        if nu == 1:
            return np.asarray(r1, dtype=np.float64)
        h2 = self._homogeneous(tau, 2)
        out: FloatArray = (h2[:, :2] - 2.0 * r1 * h1[:, 2:3] - r * h2[:, 2:3]) / wt
        return out


def straight_chord(control_points: FloatArray) -> tuple[tuple[float, float], float, float] | None:
    """``(start, heading, length)`` of the segment a NURBS traces, if it is one; else ``None``.

    A curve from its first to its last control point whose control points all lie on the
    segment between them (within ``1e-9`` of its length), in order along it, is that segment
    traced once (rational B-splines with positive weights diminish variation: the position
    along the segment never turns back).

    Examples
    --------
    >>> import numpy as np
    >>> start, heading, length = straight_chord(np.array([[0.0, 0.0], [1.5, 2.0], [3.0, 4.0]]))
    >>> start, round(heading, 12), length
    ((0.0, 0.0), 0.927295218002, 5.0)
    >>> straight_chord(np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 0.0]])) is None
    True
    """
    first, last = control_points[0], control_points[-1]
    length = float(np.hypot(*(last - first)))
    if not length > 0:
        return None
    unit = (last - first) / length
    rel = control_points - first
    along = rel @ unit
    across = rel @ np.array([-unit[1], unit[0]])
    if np.abs(across).max() > 1e-9 * length or (np.diff(along) < 0).any():
        return None
    return (float(first[0]), float(first[1])), float(np.arctan2(unit[1], unit[0])), length


def nurbs_piece(degree: Any, knots: Any, control_points: Any, weights: Any = None) -> CurvePiece:
    """Arc-length parametrised piece of a NURBS curve (see `Path.from_nurbs`).

    Knot checks (VDA 5050 3.0 requires clamped trajectories whose inner knots repeat at most
    ``degree`` times):

    * the curve must start at the first control point and end at the last one. A clamped knot
      vector (first and last knot repeated ``degree + 1`` times) guarantees it; an unclamped
      one is accepted only when the curve still meets its end control points (e.g. degree 1):
      on its domain ``[knots[degree], knots[m]]`` it then *is* the clamped curve with those
      ends, so nothing is changed. Otherwise it is refused — the path would start off its
      node.
    * an inner knot repeated more than ``degree`` times lets the position jump: refused
      unless the positions on both sides agree (to ``1e-9`` of the control polygon's
      extent); then, as for a knot repeated ``degree`` times, only a heading jump (a corner)
      is refused.

    Raises
    ------
    InvalidInputError
        Bad degree, shapes, knots (decreasing, wrong length, empty domain, a curve that does
        not start / end at its end control points, a position jump at a repeated knot),
        weights (not > 0), a curve of zero length, or a corner (heading jump at a repeated
        knot). Every knot message names ``knots``.

    Examples
    --------
    >>> from speedplan.geometry.nurbs import nurbs_piece
    >>> nurbs_piece(1, [0, 0, 1, 1], [[0, 0], [3, 4]]).length
    5.0
    """
    k = as_int("degree", degree, minimum=1)
    ctrl = as_array("control_points", control_points)
    if ctrl.ndim != 2 or ctrl.shape[1] != 2 or ctrl.shape[0] < k + 1:
        raise InvalidInputError(
            f"`control_points` must have shape (m, 2) with m >= degree + 1 = {k + 1}; "
            f"got {ctrl.shape}"
        )
    m = ctrl.shape[0]
    t = as_array("knots", knots, ndim=1)
    if t.size != m + k + 1:
        raise InvalidInputError(
            f"`knots` must have len(control_points) + degree + 1 = {m + k + 1} entries; "
            f"got {t.size}"
        )
    if (np.diff(t) < 0).any():
        i = int(np.flatnonzero(np.diff(t) < 0)[0])
        raise InvalidInputError(
            f"`knots` must be non-decreasing; knots[{i + 1}]={t[i + 1]!r} < knots[{i}]={t[i]!r}"
        )
    if not t[m] > t[k]:
        raise InvalidInputError(
            f"`knots` give an empty parameter range [knots[{k}], knots[{m}]] = [{t[k]}, {t[m]}]"
        )
    if weights is None:
        w = np.ones(m)
    else:
        w = as_array("weights", weights, ndim=1, length=m)
        if not (w > 0).all():
            i = int(np.flatnonzero(~(w > 0))[0])
            raise InvalidInputError(f"`weights` must all be > 0; weights[{i}]={w[i]!r}")
    curve = NurbsCurve(k, t, ctrl, w)
    # Before the arc-length table: a jump or an unclamped start would otherwise surface as a
    # misleading cusp message, or not at all.
    tol = _POSITION_TOLERANCE * max(float(np.ptp(ctrl, axis=0).max()), 1e-300)
    _reject_loose_ends(curve, t, k, ctrl, tol)
    _reject_jumps(curve, t, k, tol)
    piece = CurvePiece(curve)
    if not piece.length > 1e-12 * max(float(np.ptp(ctrl, axis=0).max()), 1e-300):
        raise InvalidInputError("`control_points` give a NURBS curve of zero length")
    _reject_corners(curve, t, k)
    return piece


def _reject_corners(curve: NurbsCurve, t: FloatArray, k: int) -> None:
    """A knot repeated ``degree`` times may leave only C0 continuity: refuse a heading jump."""
    values, counts = np.unique(t, return_counts=True)
    lo, hi = curve.domain
    inner = values[(counts >= k) & (values > lo) & (values < hi)]
    if inner.size == 0:
        return
    eps = 1e-7 * (hi - lo)
    left, right = curve(inner - eps, 1), curve(inner + eps, 1)
    jump = np.abs(np.angle((right[:, 0] + 1j * right[:, 1]) / (left[:, 0] + 1j * left[:, 1])))
    if (jump > 1e-3).any():
        i = int(np.argmax(jump))
        raise InvalidInputError(
            f"`knots`: the NURBS curve has a corner at parameter {inner[i]:.6g} (heading jumps "
            f"by {jump[i]:.3g} rad, a knot repeated {k} times); a vehicle must stop there — "
            "split the edge at that knot"
        )


def _point_text(p: FloatArray) -> str:
    return f"({p[0]:.6g}, {p[1]:.6g})"


def _reject_loose_ends(
    curve: NurbsCurve, t: FloatArray, k: int, ctrl: FloatArray, tol: float
) -> None:
    """The curve must start at the first control point and end at the last one."""
    lo, hi = curve.domain
    ends = curve(np.array([lo, hi]), 0)
    for end, target, which, mult in ((ends[0], ctrl[0], "start", int(np.sum(t == t[0]))),
                                     (ends[1], ctrl[-1], "end", int(np.sum(t == t[-1])))):
        gap = float(np.linalg.norm(end - target))
        if gap > tol:
            first = "first" if which == "start" else "last"
            raise InvalidInputError(
                f"`knots` are not clamped: the {first} knot is repeated {mult} times (a clamped "
                f"knot vector repeats it degree + 1 = {k + 1} times), so the curve's {which} "
                f"{_point_text(end)} is {gap:.3g} m from the {first} control point "
                f"{_point_text(target)}; repeat the {first} knot degree + 1 times (VDA 5050 "
                "trajectories are clamped NURBS)"
            )


def _reject_jumps(curve: NurbsCurve, t: FloatArray, k: int, tol: float) -> None:
    """An inner knot repeated more than ``degree`` times may leave the position discontinuous."""
    values, counts = np.unique(t, return_counts=True)
    lo, hi = curve.domain
    inner = values[(counts > k) & (values > lo) & (values < hi)]
    if inner.size == 0:
        return
    # The left limit: BSpline evaluates at a knot with the piece on its right.
    left = curve(np.nextafter(inner, -np.inf), 0)
    right = curve(inner, 0)
    gap = np.linalg.norm(right - left, axis=1)
    if (gap > tol).any():
        i = int(np.argmax(gap))
        mult = int(counts[values == inner[i]][0])
        raise InvalidInputError(
            f"`knots`: knot {inner[i]:.6g} is repeated {mult} times, more than degree = {k}, "
            f"and the NURBS curve jumps there from {_point_text(left[i])} to "
            f"{_point_text(right[i])} ({gap[i]:.3g} m); an inner knot may repeat at most "
            "`degree` times (VDA 5050) — remove the extra repeats or split the edge there"
        )

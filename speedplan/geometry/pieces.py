"""Path pieces, each parametrised by its own arc length ``u ∈ [0, length]``.

One mechanism serves every constructor: a [`Path`][speedplan.Path] is a chain of
pieces with ``length`` and vectorised ``point(u)``, ``heading(u)``, ``curvature(u)``.

* `ClothoidPiece` — curvature linear in ``u``: clothoid,
  arc (constant curvature) or line (zero curvature), evaluated to rounding.
* `CurvePiece` — a parametric curve ``r(τ)`` with derivatives (cubic spline, NURBS),
  reparametrised by arc length: a Gauss–Legendre table of ``∫|r'|``, and per cell a Chebyshev
  interpolant of its inverse ``τ(u)`` accurate to rounding (Newton's method where it is not).
* `ReversedPiece` — any piece travelled backwards.

Every piece has a ``direction`` of travel: ``+1`` forward, ``-1`` driven in reverse. ``point``
and ``curvature`` describe the curve traversed in the direction of travel; ``heading`` is the
vehicle's heading (yaw), the direction of travel on forward pieces and that plus π on reverse
ones.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, Protocol

import numpy as np
import numpy.typing as npt

from ..core.checks import FloatArray, IntArray
from ..core.errors import InvalidInputError
from ..core.numerics import GAUSS_NODES, GAUSS_WEIGHTS, SHORT_NODES, SHORT_WEIGHTS
from ._checks import as_direction

__all__ = ["GAUSS_NODES", "GAUSS_WEIGHTS", "CurvePiece", "ParametricCurve", "Piece",
           "ReversedPiece", "SubPiece"]

#: Sub-intervals per polynomial piece in the arc-length table of a `CurvePiece`.
_TABLE_SPLIT = 8
#: Distance [of a curve piece's length] within which a point is on a break of the curve (the
#: rate of its curvature is read on one side of it).
_BREAK_SNAP = 1e-12
#: At most this many rounds of halving the table cells where the arc length is not resolved.
_TABLE_HALVINGS = 40
#: At most this many safeguarded Newton steps per arc-length inversion (2-3 in practice; 60
#: bisections would shrink a cell's bracket to rounding).
_INVERSION_STEPS = 60
#: 4-point Gauss–Legendre rule on [0, 1] for the arc length over a Newton step of the
#: inversion; used for steps of at most ``_SHORT_STEP`` of a table cell, where it is exact to
#: rounding (a cell takes the 16-point rule).
_SHORT_NODES, _SHORT_WEIGHTS = SHORT_NODES, SHORT_WEIGHTS
_SHORT_STEP = 1e-3
#: Degree of the Chebyshev interpolant of ``τ(u)`` on each cell of a `CurvePiece`.
_CHEB_DEGREE = 16
#: At most this many halvings (in ``u``) of a cell whose interpolant is not accurate to
#: rounding; cells still off after them are inverted by Newton's method at every query.
_CHEB_HALVINGS = 8
#: Accepted error of the interpolant, as an arc length ``|r'| |Δτ|``, in units of the
#: curve's length (of 1 m if shorter): a few ulps (the inversion stops at ``1e-14``).
_CHEB_TOLERANCE = 2e-15
#: Accepted error of the curvature's interpolant on a cell, in units of the largest |κ| at
#: its nodes plus 1 / length: a hundred times the rounding of the curvature computed from
#: the derivatives (measured ~2e-15 on the sample NURBS); a cell above it evaluates the
#: curve at every query.
_KAPPA_TOLERANCE = 1e-13
#: At most this many Newton steps on the Chebyshev interpolant of σ(τ) for the nodes of
#: τ(u) (quadratic convergence from the linear guess: 4-5 reach rounding).
_POLY_NEWTON_STEPS = 10


def _chebyshev_matrix(degree: int) -> FloatArray:
    """Values at the Chebyshev points ``cos(πk/degree)`` to Chebyshev coefficients."""
    k = np.arange(degree + 1)
    cos = np.cos(np.pi * np.outer(k, k) / degree)  # T_i(x_k)
    scale = np.full(degree + 1, 2.0 / degree)
    scale[[0, -1]] = 1.0 / degree
    out: FloatArray = scale[:, None] * cos * np.where((k == 0) | (k == degree), 0.5, 1.0)
    return out


_CHEB_POINTS = np.cos(np.pi * np.arange(_CHEB_DEGREE + 1) / _CHEB_DEGREE)
_CHEB_MATRIX = _chebyshev_matrix(_CHEB_DEGREE)
#: Midpoints between the Chebyshev points, where an interpolant's error is largest.
_CHEB_CHECKS = np.cos(np.pi * (np.arange(_CHEB_DEGREE) + 0.5) / _CHEB_DEGREE)
#: The checks also compared with the 16-point rule (every other one, both ends included).
_GAUSS_CHECKS = np.unique(np.append(np.arange(0, _CHEB_DEGREE, 2), _CHEB_DEGREE - 1))


def _signed_curvature(d1: FloatArray, d2: FloatArray) -> FloatArray:
    """``(x'y'' - y'x'') / |r'|³`` from the first and second derivatives, shape (m, 2)."""
    cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    out: FloatArray = cross / np.linalg.norm(d1, axis=-1) ** 3
    return out


def _antiderivative(coef: FloatArray) -> FloatArray:
    """Chebyshev coefficients (one more) of ``∫_{-1}^x Σ coef[:, i] T_i``, row by row."""
    m, deg = coef.shape[0], coef.shape[1] - 1
    c = np.concatenate((coef, np.zeros((m, 2))), axis=1)
    out = np.zeros((m, deg + 2))
    i = np.arange(1, deg + 2)
    # ∫T_0 = T_1, ∫T_1 = T_2 / 4, ∫T_i = T_(i+1) / (2(i+1)) - T_(i-1) / (2(i-1)) (i >= 2).
    out[:, 1:] = (np.where(i == 1, 2.0, 1.0) * c[:, i - 1] - c[:, i + 1]) / (2.0 * i)
    # The constant term: zero at x = -1, where T_i = (-1)^i.
    out[:, 0] = -(out[:, 1:] * (-1.0) ** i).sum(axis=1)
    return out


def _clenshaw(coef: FloatArray, x: FloatArray) -> FloatArray:
    """``Σ coef[:, i] T_i(x)`` row by row (``coef`` shape ``(m, degree + 1)``, ``x`` (m,))."""
    return _clenshaw_t(np.ascontiguousarray(coef.T), x)


def _clenshaw_t(rows: FloatArray, x: FloatArray) -> FloatArray:
    """`_clenshaw` of ``rows = coef.T`` (contiguous per degree: 3x faster sums)."""
    b1 = np.zeros_like(x)
    b2 = np.zeros_like(x)
    step = np.empty_like(x)
    two_x = 2.0 * x
    for i in range(rows.shape[0] - 1, 0, -1):  # b1 <- rows[i] + 2 x b1 - b2, in place
        np.multiply(two_x, b1, out=step)
        step += rows[i]
        step -= b2
        b1, b2, step = step, b1, b2
    out: FloatArray = rows[0] + x * b1 - b2
    return out


class Piece:
    """Interface of a path piece; ``u`` is the local arc length in ``[0, length]`` [m].

    ``direction`` is ``+1`` (forward) or ``-1`` (driven in reverse).
    """

    length: float
    direction: int = 1

    def point(self, u: FloatArray) -> FloatArray:  # pragma: no cover - interface
        """Positions at local arc lengths ``u``, shape ``u.shape + (2,)`` [m]."""
        raise NotImplementedError

    def heading(self, u: FloatArray) -> FloatArray:  # pragma: no cover - interface
        """Vehicle headings at local arc lengths ``u`` [rad], continuous along the piece."""
        raise NotImplementedError

    def curvature(self, u: FloatArray) -> FloatArray:  # pragma: no cover - interface
        """Signed curvatures [1/m] (positive: turning left, in the direction of travel)."""
        raise NotImplementedError

    def curvature_rate(self, u: FloatArray) -> FloatArray:
        """``dκ/du`` [1/m²]: a central difference inside the piece (one-sided at its ends).

        The step is ``1e-5`` of the piece (error of order step² times the third derivative
        of the curvature); pieces whose curvature is linear in ``u`` override it exactly.
        """
        u = np.clip(np.asarray(u, dtype=np.float64), 0.0, self.length)
        step = 1e-5 * self.length
        lo, hi = np.maximum(u - step, 0.0), np.minimum(u + step, self.length)
        out: FloatArray = (self.curvature(hi) - self.curvature(lo)) / (hi - lo)
        return out

    def curvature_rate_before(self, u: FloatArray) -> FloatArray:
        """``dκ/du`` [1/m²] on the side before ``u``.

        At a `rate_breaks` point, the rate the stretch before it ends with
        (`curvature_rate` gives the one after it).
        """
        return self.curvature_rate(u)

    @property
    def rate_breaks(self) -> FloatArray:
        """Local arc lengths [m] inside the piece where the curvature rate may jump.

        None for a line, an arc or a clothoid; the knots of a spline or NURBS piece (a cubic
        one is C² there: its curvature is continuous, its rate is not).
        """
        return np.zeros(0)

    def evaluate(self, u: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``(point, heading, curvature)`` at once (pieces share work where they can)."""
        return self.point(u), self.heading(u), self.curvature(u)

    @property
    def straight(self) -> bool:
        """Whether the curvature is exactly 0 along the whole piece (a line).

        ``False`` unless the piece's own formula says so (a spline or NURBS piece that
        happens to be straight is not recognised).
        """
        return False

    def reversed(self, swap_direction: bool = False) -> Piece:
        """The piece travelled from its end to its start.

        By default the direction flag is kept and the vehicle turned around (heading + π):
        the mirrored manoeuvre. ``swap_direction=True`` flips the flag and keeps the heading:
        the vehicle retraces its poses backwards (e.g. backs out the way it drove in).
        """
        return ReversedPiece(self, swap_direction)


class ParametricCurve(Protocol):
    """A picklable curve ``r(τ)``: ``curve(tau, nu)`` is the ``nu``-th derivative, shape (m, 2).

    ``breaks`` are the parameters where its polynomial pieces join (quadrature never straddles
    them), from the first to the last parameter of the curve.
    """

    @property
    def breaks(self) -> FloatArray:  # pragma: no cover - protocol
        """Parameters of the joins, increasing, first and last included."""
        ...

    def __call__(self, tau: FloatArray, nu: int) -> FloatArray:  # pragma: no cover - protocol
        """``nu``-th derivative (0, 1 or 2) at parameters ``tau`` (1-D), shape (m, 2)."""
        ...


@dataclass(frozen=True, eq=False)
class CurvePiece(Piece):
    """A parametric curve reparametrised by arc length.

    The arc length ``σ(τ) = ∫|r'|`` is tabulated with a 16-point Gauss–Legendre rule on 8
    cells per polynomial piece, each halved until the rule resolves it (see
    `_arc_table`); ``τ(u)`` solves ``σ(τ) = u`` by Newton's method kept inside the
    bracketing table cell, so ``point(u)`` moves at unit speed. Queries use a degree-16
    Chebyshev interpolant of ``τ(u)`` per cell instead, built at construction and checked
    against the 16-point rule between its nodes (cells halved until it agrees to a few ulps,
    see `_interpolate`): one Clenshaw sum and one curve evaluation per query. The
    curvature has its own interpolants on the same cells (`_interpolate_curvature`):
    a curvature query is one Clenshaw sum.
    """

    curve: ParametricCurve
    direction: int = 1
    length: float = field(init=False)
    _tau: FloatArray = field(init=False, repr=False)
    _arc: FloatArray = field(init=False, repr=False)
    _theta: FloatArray = field(init=False, repr=False)
    _dtau: FloatArray = field(init=False, repr=False)
    # Chebyshev interpolants of τ(u): cell starts in u (and the end), the τ at both ends of
    # each cell, the coefficients of (τ - τ_lo) / (τ_hi - τ_lo) in 2 (u - u_lo) / span - 1
    # (one row per degree, one column per cell),
    # and whether the interpolant is accurate (else the cell inverts by Newton per query).
    _cheb_u: FloatArray = field(init=False, repr=False)
    _cheb_tau: FloatArray = field(init=False, repr=False)
    _cheb_coef: FloatArray = field(init=False, repr=False)
    _cheb_ok: npt.NDArray[np.bool_] = field(init=False, repr=False)
    # Chebyshev interpolants of κ(u) on the same cells (one row per degree, one column per
    # cell) and whether each is accurate (else the curve is evaluated per query).
    _kappa_coef: FloatArray = field(init=False, repr=False)
    _kappa_ok: npt.NDArray[np.bool_] = field(init=False, repr=False)
    # Arc lengths of the curve's interior breaks (`rate_breaks`).
    _breaks_u: FloatArray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "direction", as_direction("direction", self.direction))
        b = np.asarray(self.curve.breaks, dtype=np.float64)
        frac = np.linspace(0.0, 1.0, _TABLE_SPLIT + 1)[:-1]
        coarse = np.append((b[:-1, None] + np.diff(b)[:, None] * frac[None, :]).ravel(), b[-1])
        tau, cells = self._arc_table(coarse)
        arc = np.concatenate(([0.0], np.cumsum(cells)))
        d1 = self.curve(tau, 1)
        speed = np.linalg.norm(d1, axis=1)
        mean_speed = arc[-1] / max(float(b[-1] - b[0]), 1e-300)
        # Tested on the unrefined nodes: the refinement puts nodes into slow stretches of
        # curves that do not turn back, and would refuse them. Zero length: callers say.
        coarse_speed = np.linalg.norm(self.curve(coarse, 1), axis=1)
        if mean_speed > 0 and coarse_speed.min() <= 1e-6 * mean_speed:
            # |r'| = 0: the curve stops and turns back (a cusp); heading and curvature are
            # undefined there and a vehicle would have to reverse.
            i = int(np.argmin(coarse_speed))
            raise InvalidInputError(
                f"the curve reverses direction (a cusp, |r'| = 0) near parameter "
                f"{coarse[i]:.6g}; the waypoints or control points double back — split the "
                "path there"
            )
        # Unwrapped headings at the table nodes anchor a continuous heading(u); a vehicle
        # driving the curve in reverse faces the other way.
        theta = np.unwrap(np.arctan2(d1[:, 1], d1[:, 0])) + (np.pi if self.direction < 0 else 0.0)
        set_ = object.__setattr__
        set_(self, "_tau", tau)
        set_(self, "_arc", arc)
        set_(self, "_theta", theta)
        set_(self, "_dtau", 1.0 / np.maximum(speed, 1e-300))  # dτ/du at the table nodes
        set_(self, "length", float(arc[-1]))
        inner = b[1:-1]  # the table holds every break as a node: their arc lengths are exact
        set_(self, "_breaks_u", arc[np.searchsorted(tau, inner)] if inner.size else np.zeros(0))
        self._interpolate()

    def _interpolate(self) -> None:
        """Chebyshev interpolants of ``τ(u)`` per table cell, halved where not accurate.

        Each interpolant is checked halfway between its nodes, where an interpolant's error
        peaks, and accepted within ``_CHEB_TOLERANCE`` of the length (see
        `_fit_cells`); a cell still off after ``_CHEB_HALVINGS`` halvings keeps
        Newton's method. A query is then one Clenshaw sum instead of Newton steps of 16-point
        integrals of ``|r'|``.
        """
        u_lo, u_hi = self._arc[:-1], self._arc[1:]
        t_lo, t_hi = self._tau[:-1], self._tau[1:]
        tol = _CHEB_TOLERANCE * max(self.length, 1.0)
        done: list[tuple[npt.NDArray[np.generic], ...]] = []
        for rnd in range(_CHEB_HALVINGS + 1):
            coef, ok = self._fit_cells(u_lo, u_hi, t_lo, t_hi, tol)
            keep = ok | (rnd == _CHEB_HALVINGS) | ~(u_hi - u_lo > 4 * np.spacing(u_hi))
            done.append((u_lo[keep], t_lo[keep], t_hi[keep], coef[keep], ok[keep]))
            if keep.all():
                break
            bad = ~keep
            mid = 0.5 * (u_lo[bad] + u_hi[bad])
            t_mid = self._parameter(*self._cell(mid), rel_tol=0.0) if mid.size else mid
            u_lo, u_hi = np.concatenate((u_lo[bad], mid)), np.concatenate((mid, u_hi[bad]))
            t_lo = np.concatenate((t_lo[bad], t_mid))
            t_hi = np.concatenate((t_mid, t_hi[bad]))
        u0, lo, hi, coef, ok = (np.concatenate(parts) for parts in zip(*done, strict=True))
        order = np.argsort(u0, kind="stable")
        set_ = object.__setattr__
        set_(self, "_cheb_u", np.append(u0[order], self.length))
        set_(self, "_cheb_tau", np.column_stack((lo[order], hi[order])))
        set_(self, "_cheb_coef", np.ascontiguousarray(coef[order].T))
        set_(self, "_cheb_ok", ok[order])
        self._interpolate_curvature()

    def _interpolate_curvature(self) -> None:
        """Chebyshev interpolants of ``κ(u)`` on the cells of ``τ(u)``'s interpolants.

        A curvature query on a spline or NURBS path then costs one Clenshaw sum instead of an
        inversion and three derivative evaluations; ``plan()`` evaluates the curvature at
        eight points per grid interval. Each interpolant is checked halfway between its nodes
        against the curvature from the derivatives and kept within ``_KAPPA_TOLERANCE``.
        """
        u0, u1 = self._cheb_u[:-1], self._cheb_u[1:]
        half = 0.5 * (u1 - u0)
        m = _CHEB_CHECKS.size
        # A curve of zero length (refused by its constructor after this) or with |r'| = 0
        # gives NaN here: such a cell fails its check and keeps the direct evaluation.
        with np.errstate(divide="ignore", invalid="ignore"):
            kappa = self._direct_curvature(
                (u0[:, None] + half[:, None] * (_CHEB_POINTS[None, :] + 1.0)).ravel()
            ).reshape(u0.size, -1)
            coef = kappa @ _CHEB_MATRIX.T
            checks = self._direct_curvature(
                (u0[:, None] + half[:, None] * (_CHEB_CHECKS[None, :] + 1.0)).ravel())
            got = _clenshaw(np.repeat(coef, m, axis=0), np.tile(_CHEB_CHECKS, u0.size))
            scale = np.abs(kappa).max(axis=1) + 1.0 / max(self.length, 1e-300)
            err = np.abs(got - checks).reshape(-1, m).max(axis=1)
        set_ = object.__setattr__
        set_(self, "_kappa_coef", np.ascontiguousarray(coef.T))
        set_(self, "_kappa_ok", err <= _KAPPA_TOLERANCE * scale)

    def _fit_cells(self, u_lo: FloatArray, u_hi: FloatArray, t_lo: FloatArray,
                   t_hi: FloatArray, tol: float) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
        """Coefficients of each cell's interpolant and whether it passes the check.

        The nodes ``τ(u_k)`` invert a Chebyshev interpolant of ``σ(τ)`` on the cell (from
        ``|r'|`` at its Chebyshev points: one curve evaluation per point, not Newton steps of
        integrals). Halfway between the nodes, ``σ`` at the interpolated ``τ`` must give back
        ``u``: from σ's interpolant at all of them, from the 16-point rule of ``|r'|`` over
        the cell's start to ``τ`` at every other one. Where ``σ`` is not resolved by its
        interpolant, the nodes are off and the rule fails the cell.
        """
        n = u_lo.size
        width = np.where(t_hi > t_lo, t_hi - t_lo, 1.0)
        half = 0.5 * width[:, None]
        taus = t_lo[:, None] + half * (_CHEB_POINTS[None, :] + 1.0)
        speed = np.linalg.norm(self.curve(taus.ravel(), 1), axis=-1).reshape(taus.shape)
        a = speed @ _CHEB_MATRIX.T  # |r'| in y ∈ [-1, 1], τ = t_lo + (width / 2) (y + 1)
        sigma = _antiderivative(a) * half  # σ(τ) - σ(t_lo), zero at y = -1
        # Targets: u at the Chebyshev points of [u_lo, u_hi]; Newton on the polynomials from
        # the linear guess, kept in [-1, 1] (σ grows: |r'| > 0 on cells without cusps).
        target = (0.5 * (u_hi - u_lo))[:, None] * (_CHEB_POINTS[None, :] + 1.0)
        y = np.repeat(_CHEB_POINTS[None, :], n, axis=0).copy()
        rows = np.repeat(np.arange(n), _CHEB_POINTS.size)
        ca, cs = a.T[:, rows], sigma.T[:, rows]
        yf, tf, hf = y.ravel(), target.ravel(), np.repeat(half[:, 0], _CHEB_POINTS.size)
        last = False
        for _ in range(_POLY_NEWTON_STEPS):
            step = (_clenshaw_t(cs, yf) - tf) / np.maximum(hf * _clenshaw_t(ca, yf), 1e-300)
            yf = np.clip(yf - step, -1.0, 1.0)
            if last:
                break
            # Quadratic convergence: after a step below 1e-9, one more reaches rounding.
            last = not np.abs(step).max(initial=0.0) > 1e-9
        nodes = t_lo[:, None] + half * (yf.reshape(y.shape) + 1.0)
        nodes[:, 0], nodes[:, -1] = t_hi, t_lo  # x = 1 is the cell's end, x = -1 its start
        coef = ((nodes - t_lo[:, None]) / width[:, None]) @ _CHEB_MATRIX.T
        m = _CHEB_CHECKS.size
        got = t_lo[:, None] + width[:, None] * _clenshaw(
            np.repeat(coef, m, axis=0), np.tile(_CHEB_CHECKS, n)).reshape(-1, m)
        got = np.clip(got, t_lo[:, None], t_hi[:, None])
        u_check = u_lo[:, None] + (0.5 * (u_hi - u_lo))[:, None] * (_CHEB_CHECKS[None, :] + 1.0)
        y_got = ((got - t_lo[:, None]) / half - 1.0).ravel()
        rows_m = np.repeat(np.arange(n), m)
        off = u_lo[:, None] + _clenshaw_t(sigma.T[:, rows_m], y_got).reshape(got.shape) - u_check
        # σ's interpolant against the 16-point rule at every other check (it is smooth where
        # it passes; τ(u)'s interpolant is checked at all of them above).
        sub = got[:, _GAUSS_CHECKS]
        arc = self._speed_integral(np.repeat(t_lo, sub.shape[1]), sub.ravel())
        gauss = u_lo[:, None] + arc.reshape(sub.shape) - u_check[:, _GAUSS_CHECKS]
        speed = np.linalg.norm(self.curve(got.ravel(), 1), axis=-1).reshape(got.shape)
        # Below ``tol`` where |r'| is so large that an ulp of τ exceeds it: Newton's method
        # cannot do better there either.
        floor = speed * np.spacing(np.abs(got)) + 4.0 * np.spacing(np.abs(u_check))
        ok = ((np.abs(off) <= tol + floor).all(axis=1)
              & (np.abs(gauss) <= tol + floor[:, _GAUSS_CHECKS]).all(axis=1))
        return coef, ok

    def _arc_table(self, nodes: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Table nodes ``τ`` (``nodes``, refined) and the arc length of each cell between them.

        Cells are halved until one rule over the cell and one over each half agree to 1e-15
        of the curve's length (of 1 m if shorter): where ``|r'|`` varies by orders of
        magnitude within a cell (a NURBS with weights 200 and 0.01), a single rule is off by
        metres and the inversion would not converge.
        """
        tau = nodes
        cells = self._speed_integral(tau[:-1], tau[1:])
        tol = 1e-15 * max(float(np.sum(cells)), 1.0)
        pending = np.ones(cells.size, dtype=bool)  # cells not yet compared with their halves
        for _ in range(_TABLE_HALVINGS):
            lo, hi = tau[:-1][pending], tau[1:][pending]
            mid = 0.5 * (lo + hi)
            left, right = self._speed_integral(lo, mid), self._speed_integral(mid, hi)
            bad = (np.abs(left + right - cells[pending]) > tol) & (mid > lo) & (mid < hi)
            if not bad.any():
                break
            idx = np.flatnonzero(pending)[bad]
            count = np.ones(cells.size, dtype=np.intp)
            count[idx] = 2
            first = np.cumsum(count) - count  # where each old cell starts in the new table
            new_tau, new_cells = np.empty(count.sum() + 1), np.empty(count.sum())
            new_tau[first], new_tau[-1], new_cells[first] = tau[:-1], tau[-1], cells
            new_cells[first[idx]] = left[bad]
            new_tau[first[idx] + 1], new_cells[first[idx] + 1] = mid[bad], right[bad]
            pending = np.zeros(new_cells.size, dtype=bool)
            pending[first[idx]] = pending[first[idx] + 1] = True
            tau, cells = new_tau, new_cells
        else:
            raise InvalidInputError(
                f"the curve's arc length is not resolved after {_TABLE_HALVINGS} halvings of "
                f"its cells near parameter {tau[int(np.argmax(pending))]:.6g} (its speed |r'| "
                "varies too strongly there); check the weights and control points"
            )
        return tau, cells

    def _speed_integral(
        self, a: FloatArray, b: FloatArray, rule: tuple[FloatArray, FloatArray] = (
            GAUSS_NODES, GAUSS_WEIGHTS)
    ) -> FloatArray:
        """``∫_a^b |r'(τ)| dτ`` elementwise (one Gauss–Legendre ``rule`` per interval)."""
        x, weights = rule
        width = (b - a)[:, None]
        nodes = (a[:, None] + width * x[None, :]).ravel()
        speed = np.linalg.norm(self.curve(nodes, 1), axis=-1).reshape(-1, x.size)
        out: FloatArray = (speed * width) @ weights
        return out

    def _cell(self, u: FloatArray) -> tuple[FloatArray, IntArray]:
        """Flattened, clipped ``u`` and the index of its table cell."""
        flat = np.clip(np.asarray(u, dtype=np.float64).ravel(), 0.0, self.length)
        j = np.clip(np.searchsorted(self._arc, flat, side="right") - 1, 0, self._tau.size - 2)
        return flat, j

    def parameter(self, u: FloatArray) -> FloatArray:
        """Curve parameter ``τ`` at local arc lengths ``u`` (flattened)."""
        flat, j = self._cell(u)
        if not hasattr(self, "_cheb_u"):  # while the interpolants are being built
            return self._parameter(flat, j)
        return self._interpolated(flat, j)

    def _interpolated(self, flat: FloatArray, j: IntArray) -> FloatArray:
        """``τ(u)`` from the cells' interpolants (Newton where a cell has none)."""
        c = np.clip(np.searchsorted(self._cheb_u, flat, side="right") - 1, 0,
                    self._cheb_u.size - 2)
        u0, u1 = self._cheb_u[c], self._cheb_u[c + 1]
        x = 2.0 * (flat - u0) / np.maximum(u1 - u0, 1e-300) - 1.0
        lo, hi = self._cheb_tau[c, 0], self._cheb_tau[c, 1]
        tau = np.clip(lo + (hi - lo) * _clenshaw_t(self._cheb_coef[:, c], x), lo, hi)
        # Exactly the table's τ at the ends of a cell (the sum is off by rounding there): a
        # NURBS path starts and ends on its end control points to the last bit.
        tau = np.where(flat <= u0, lo, np.where(flat >= u1, hi, tau))
        newton = ~self._cheb_ok[c]
        if newton.any():
            tau[newton] = self._parameter(flat[newton], j[newton])
        out: FloatArray = tau
        return out

    def _parameter(self, flat: FloatArray, j: IntArray, rel_tol: float = 1e-14) -> FloatArray:
        lo, hi = self._tau[j], self._tau[j + 1]
        span = np.maximum(self._arc[j + 1] - self._arc[j], 1e-300)
        # Cubic Hermite start from τ and dτ/du = 1/|r'| at the cell's ends: one Newton step
        # (a 16-point integral per position) fewer than a linear start on nurbs_edge.json.
        x = (flat - self._arc[j]) / span
        x2, x3 = x * x, x * x * x
        tau = ((2 * x3 - 3 * x2 + 1) * lo + (-2 * x3 + 3 * x2) * hi
               + span * ((x3 - 2 * x2 + x) * self._dtau[j] + (x3 - x2) * self._dtau[j + 1]))
        tau = np.clip(tau, lo, hi)
        tol = rel_tol * max(self.length, 1.0)
        f = self._arc[j] + self._speed_integral(lo, tau) - flat  # σ(τ) - u
        a, b = lo.copy(), hi.copy()  # σ(a) <= u <= σ(b)
        act = np.flatnonzero(np.abs(f) > tol)  # positions still iterating
        for _ in range(_INVERSION_STEPS):
            if act.size == 0:
                break
            fa, ta = f[act], tau[act]
            a[act] = np.where(fa < 0, ta, a[act])
            b[act] = np.where(fa < 0, b[act], ta)
            speed = np.linalg.norm(self.curve(ta, 1), axis=-1)
            # Newton inside the bracket, bisection otherwise: converges however |r'| varies.
            new = ta - fa / np.maximum(speed, 1e-300)
            new = np.where((new >= a[act]) & (new <= b[act]), new, 0.5 * (a[act] + b[act]))
            # Where |r'| is huge, a step below τ's rounding still moves σ by > tol: stop.
            moved = new != ta
            act, new, fa, ta = act[moved], new[moved], fa[moved], ta[moved]
            # σ(new) - u = f + ∫_τ^new |r'|: over a short step 4 points do what 16 do over
            # the cell from its start (half the time of the inversion on nurbs_edge.json).
            near = np.abs(new - ta) <= _SHORT_STEP * (hi[act] - lo[act])
            fa[near] += self._speed_integral(ta[near], new[near], (_SHORT_NODES, _SHORT_WEIGHTS))
            far = ~near
            if np.any(far):
                k = act[far]
                fa[far] = self._arc[j[k]] + self._speed_integral(lo[k], new[far]) - flat[k]
            f[act], tau[act] = fa, new
            act = act[np.abs(fa) > tol]
        out: FloatArray = tau
        return out

    def evaluate(self, u: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``(point, heading, curvature)`` from one arc-length inversion."""
        shape = np.shape(u)
        flat, j = self._cell(u)
        tau = self._interpolated(flat, j)
        r, d1, _ = self._derivatives(tau)
        raw = np.arctan2(d1[:, 1], d1[:, 0]) + (np.pi if self.direction < 0 else 0.0)
        # Nearest 2π-branch to the heading interpolated in the table cell.
        w = (flat - self._arc[j]) / np.maximum(self._arc[j + 1] - self._arc[j], 1e-300)
        ref = (1.0 - w) * self._theta[j] + w * self._theta[j + 1]
        theta = raw + 2.0 * np.pi * np.round((ref - raw) / (2.0 * np.pi))
        kappa = self.curvature(flat)  # the interpolant: the same numbers as curvature()
        return r.reshape(*shape, 2), theta.reshape(shape), kappa.reshape(shape)

    def _derivatives(self, tau: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``r, r', r''`` at ``tau``: in one pass when the curve offers it (NURBS)."""
        both = getattr(self.curve, "derivatives", None)
        if both is not None:
            out: tuple[FloatArray, FloatArray, FloatArray] = both(tau)
            return out
        return self.curve(tau, 0), self.curve(tau, 1), self.curve(tau, 2)

    def point(self, u: FloatArray) -> FloatArray:
        """Positions at local arc lengths ``u`` [m]."""
        return self.curve(self.parameter(u), 0).reshape(*np.shape(u), 2)

    def heading(self, u: FloatArray) -> FloatArray:
        """Direction of ``r'(τ)`` (+ π in reverse) [rad], continuous along the piece."""
        return self.evaluate(u)[1]

    def curvature(self, u: FloatArray) -> FloatArray:
        """``(x'y'' - y'x'') / |r'|³`` [1/m], from the cells' interpolants of ``κ(u)``."""
        flat = np.clip(np.asarray(u, dtype=np.float64).ravel(), 0.0, self.length)
        c = np.clip(np.searchsorted(self._cheb_u, flat, side="right") - 1, 0,
                    self._cheb_u.size - 2)
        u0, u1 = self._cheb_u[c], self._cheb_u[c + 1]
        x = np.clip(2.0 * (flat - u0) / np.maximum(u1 - u0, 1e-300) - 1.0, -1.0, 1.0)
        kappa = _clenshaw_t(np.take(self._kappa_coef, c, axis=1), x)
        direct = ~self._kappa_ok[c]
        if direct.any():
            kappa[direct] = self._direct_curvature(flat[direct])
        return kappa.reshape(np.shape(u))

    def _direct_curvature(self, flat: FloatArray) -> FloatArray:
        """The curvature from ``r'`` and ``r''`` at the inverted parameters of ``flat``."""
        tau = self._interpolated(*self._cell(flat))
        _, d1, d2 = self._derivatives(tau)
        return _signed_curvature(d1, d2)

    @property
    def rate_breaks(self) -> FloatArray:
        """The arc lengths [m] of the curve's interior breaks (knots)."""
        return self._breaks_u.copy()

    def curvature_rate(self, u: FloatArray) -> FloatArray:
        """The central difference of `Piece.curvature_rate`, within the polynomial piece.

        The difference does not straddle a break, where the rate jumps: at a break it is the
        piece's after it (`curvature_rate_before` gives the one before).
        """
        return self._rate(u, side="right")

    def curvature_rate_before(self, u: FloatArray) -> FloatArray:
        """`curvature_rate`, but at a break the polynomial piece's before it."""
        return self._rate(u, side="left")

    def _rate(self, u: FloatArray, side: Literal["left", "right"]) -> FloatArray:
        u = np.clip(np.asarray(u, dtype=np.float64), 0.0, self.length)
        edges = np.concatenate(([0.0], self._breaks_u, [self.length]))
        # A break reached through other arithmetic (a reversed or shifted piece's L - (L - b))
        # lies a few ulps off: within _BREAK_SNAP of the length it is the break.
        near = np.clip(np.searchsorted(edges, u), 1, edges.size - 1)
        near = np.where(u - edges[near - 1] < edges[near] - u, near - 1, near)
        u = np.where(np.abs(u - edges[near]) <= _BREAK_SNAP * self.length, edges[near], u)
        k = np.clip(np.searchsorted(edges, u, side=side) - 1, 0, edges.size - 2)
        step = 1e-5 * self.length
        lo, hi = np.maximum(u - step, edges[k]), np.minimum(u + step, edges[k + 1])
        kappa = self.curvature(np.concatenate((lo.ravel(), hi.ravel())))
        out: FloatArray = ((kappa[lo.size:] - kappa[:lo.size]).reshape(u.shape) / (hi - lo))
        return out


@dataclass(frozen=True, eq=False)
class ReversedPiece(Piece):
    """``piece`` travelled backwards: curvature negated.

    By default its direction flag is kept and the heading turned by π (the vehicle faces the
    new direction of travel if it did the old one); ``swap_direction=True`` flips the flag and
    keeps the heading (the vehicle retraces its poses backwards).
    """

    piece: Piece
    swap_direction: bool = False

    @property
    def length(self) -> float:  # type: ignore[override]
        """Length of the underlying piece [m]."""
        return self.piece.length

    @property
    def direction(self) -> int:  # type: ignore[override]
        """Direction of travel: the piece's, flipped if ``swap_direction``."""
        return -self.piece.direction if self.swap_direction else self.piece.direction

    def _mirror(self, u: FloatArray) -> FloatArray:
        out: FloatArray = self.piece.length - np.asarray(u, dtype=np.float64)
        return out

    def _turn(self) -> float:
        return 0.0 if self.swap_direction else np.pi

    def evaluate(self, u: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``(point, heading, curvature)`` travelled backwards."""
        xy, theta, kappa = self.piece.evaluate(self._mirror(u))
        return xy, theta + self._turn(), -kappa

    def point(self, u: FloatArray) -> FloatArray:
        """Positions, travelled backwards [m]."""
        return self.piece.point(self._mirror(u))

    def heading(self, u: FloatArray) -> FloatArray:
        """Headings turned by π (kept if ``swap_direction``) [rad]."""
        out: FloatArray = self.piece.heading(self._mirror(u)) + self._turn()
        return out

    def curvature(self, u: FloatArray) -> FloatArray:
        """Curvatures with the opposite sign [1/m]."""
        out: FloatArray = -self.piece.curvature(self._mirror(u))
        return out

    def curvature_rate(self, u: FloatArray) -> FloatArray:
        """``d(-κ(L - u))/du = κ'(L - u)`` [1/m²]; after ``u`` is before ``L - u``."""
        return self.piece.curvature_rate_before(self._mirror(u))

    def curvature_rate_before(self, u: FloatArray) -> FloatArray:
        """`curvature_rate` on the side before ``u``: after ``L - u`` on the piece."""
        return self.piece.curvature_rate(self._mirror(u))

    @property
    def rate_breaks(self) -> FloatArray:
        """The piece's breaks, mirrored [m]."""
        out: FloatArray = (self.piece.length - self.piece.rate_breaks)[::-1]
        return out

    @property
    def straight(self) -> bool:
        """Whether the underlying piece is a line."""
        return self.piece.straight

    def reversed(self, swap_direction: bool = False) -> Piece:
        """The original piece when reversed the same way; otherwise a nested reversal."""
        if swap_direction == self.swap_direction:
            return self.piece
        return ReversedPiece(self, swap_direction)


@dataclass(frozen=True, eq=False)
class SubPiece(Piece):
    """The stretch ``[lo, lo + length]`` of ``piece``, with its own arc length from 0."""

    piece: Piece
    lo: float
    sub_length: float

    @property
    def length(self) -> float:  # type: ignore[override]
        """Length of the stretch [m]."""
        return self.sub_length

    @property
    def direction(self) -> int:  # type: ignore[override]
        """Direction of travel of the underlying piece."""
        return self.piece.direction

    @property
    def straight(self) -> bool:
        """Whether the underlying piece is a line."""
        return self.piece.straight

    def _shift(self, u: FloatArray) -> FloatArray:
        out: FloatArray = self.lo + np.clip(np.asarray(u, dtype=np.float64), 0.0,
                                            self.sub_length)
        return out

    def evaluate(self, u: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``(point, heading, curvature)`` of the underlying piece."""
        return self.piece.evaluate(self._shift(u))

    def point(self, u: FloatArray) -> FloatArray:
        """Positions [m]."""
        return self.piece.point(self._shift(u))

    def heading(self, u: FloatArray) -> FloatArray:
        """Vehicle headings [rad]."""
        return self.piece.heading(self._shift(u))

    def curvature(self, u: FloatArray) -> FloatArray:
        """Curvatures [1/m]."""
        return self.piece.curvature(self._shift(u))

    def curvature_rate(self, u: FloatArray) -> FloatArray:
        """``dκ/du`` [1/m²]; at the stretch's end, the rate before it."""
        q = self._shift(u)
        out = self.piece.curvature_rate(q)
        end = q >= self.lo + self.sub_length
        if np.any(end):  # the piece may go on with another rate after a break there
            out = np.where(end, self.piece.curvature_rate_before(q), out)
        return out

    def curvature_rate_before(self, u: FloatArray) -> FloatArray:
        """``dκ/du`` [1/m²] on the side before ``u``; at the stretch's start, after it."""
        q = self._shift(u)
        out = self.piece.curvature_rate_before(q)
        start = q <= self.lo
        if np.any(start):
            out = np.where(start, self.piece.curvature_rate(q), out)
        return out

    @property
    def rate_breaks(self) -> FloatArray:
        """The piece's breaks inside the stretch, in its own arc length [m]."""
        b = self.piece.rate_breaks - self.lo
        out: FloatArray = b[(b > 0.0) & (b < self.sub_length)]
        return out

"""Path pieces, each parametrised by its own arc length ``u ∈ [0, length]``.

Two kinds cover every constructor:

* :class:`ClothoidPiece` — heading quadratic in ``u`` (curvature linear): a clothoid, and with
  constant curvature an arc or a line. Positions are integrals of ``(cos θ, sin θ)``, computed by
  Gauss–Legendre quadrature from a table of knots spaced so that the heading turns by at most
  0.25 rad between them: accurate to rounding.
* :class:`CurvePiece` — a parametric curve ``r(τ)`` with derivatives (cubic spline, NURBS),
  reparametrised by arc length through a quadrature table inverted by Newton's method.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .._checks import FloatArray

__all__ = ["ClothoidPiece", "CurvePiece", "Piece", "ReversedPiece"]

_GX, _GW = np.polynomial.legendre.leggauss(16)
_GX, _GW = 0.5 * (_GX + 1.0), 0.5 * _GW


class Piece:
    """Interface: ``length`` and vectorised ``point(u)``, ``heading(u)``, ``curvature(u)``."""

    length: float

    def point(self, u: FloatArray) -> FloatArray:  # pragma: no cover - interface
        """Positions at local arc lengths ``u``, shape ``u.shape + (2,)`` [m]."""
        raise NotImplementedError

    def heading(self, u: FloatArray) -> FloatArray:  # pragma: no cover - interface
        """Headings at local arc lengths ``u`` [rad]."""
        raise NotImplementedError

    def curvature(self, u: FloatArray) -> FloatArray:  # pragma: no cover - interface
        """Signed curvatures at local arc lengths ``u`` [1/m]."""
        raise NotImplementedError


@dataclass(frozen=True)
class ClothoidPiece(Piece):
    """Curvature ``k0 + (k1 - k0) u / length`` from ``start`` with heading ``theta0``."""

    start: tuple[float, float]
    theta0: float
    length: float
    k0: float
    k1: float
    _knots: FloatArray = field(init=False, repr=False, compare=False)
    _knot_xy: FloatArray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        turn = abs(self.k0) * self.length + 0.5 * abs(self.k1 - self.k0) * self.length
        m = int(np.clip(np.ceil(turn / 0.25), 1, 100_000))
        knots = np.linspace(0.0, self.length, m + 1)
        steps = self._integrate(knots[:-1], knots[1:])
        xy = np.asarray(self.start, dtype=np.float64) + np.vstack(
            (np.zeros((1, 2)), np.cumsum(steps, axis=0))
        )
        object.__setattr__(self, "_knots", knots)
        object.__setattr__(self, "_knot_xy", xy)

    def heading(self, u: FloatArray) -> FloatArray:
        """Heading ``θ0 + k0 u + (k1 - k0) u² / (2 length)`` [rad]."""
        u = np.asarray(u, dtype=np.float64)
        sharpness = (self.k1 - self.k0) / self.length
        out: FloatArray = self.theta0 + self.k0 * u + 0.5 * sharpness * u * u
        return out

    def curvature(self, u: FloatArray) -> FloatArray:
        """Curvature, linear from ``k0`` to ``k1`` [1/m]."""
        u = np.asarray(u, dtype=np.float64)
        out: FloatArray = self.k0 + (self.k1 - self.k0) * u / self.length
        return out

    def _integrate(self, a: FloatArray, b: FloatArray) -> FloatArray:
        width = (b - a)[:, None]
        th = self.heading(a[:, None] + width * _GX[None, :])
        return np.column_stack(((np.cos(th) * width) @ _GW, (np.sin(th) * width) @ _GW))

    def point(self, u: FloatArray) -> FloatArray:
        """Positions: the nearest knot's position plus a 16-point quadrature from it [m]."""
        u = np.clip(np.asarray(u, dtype=np.float64), 0.0, self.length)
        flat = u.ravel()
        j = np.clip(np.searchsorted(self._knots, flat, side="right") - 1, 0, self._knots.size - 2)
        out = self._knot_xy[j] + self._integrate(self._knots[j], flat)
        return out.reshape(*u.shape, 2)


@dataclass(frozen=True)
class CurvePiece(Piece):
    """A parametric curve reparametrised by arc length.

    ``curve(tau, nu)`` returns the ``nu``-th derivative of ``r`` at parameters ``tau``, shape
    ``(..., 2)``, for ``tau ∈ [tau0, tau1]``; ``breaks`` are parameter values where the curve's
    polynomial pieces join (quadrature never straddles them).
    """

    curve: Callable[[FloatArray, int], FloatArray]
    breaks: FloatArray
    length: float = field(init=False)
    _tau: FloatArray = field(init=False, repr=False, compare=False)
    _arc: FloatArray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        # Table: 8 sub-intervals per polynomial piece, 16-point Gauss–Legendre on each.
        b = np.asarray(self.breaks, dtype=np.float64)
        tau = np.unique(np.concatenate([np.linspace(b[i], b[i + 1], 9) for i in range(b.size - 1)]))
        seg = self._speed_integral(tau[:-1], tau[1:])
        arc = np.concatenate(([0.0], np.cumsum(seg)))
        object.__setattr__(self, "_tau", tau)
        object.__setattr__(self, "_arc", arc)
        object.__setattr__(self, "length", float(arc[-1]))

    def _speed_integral(self, a: FloatArray, b: FloatArray) -> FloatArray:
        width = (b - a)[:, None]
        d1 = self.curve((a[:, None] + width * _GX[None, :]).ravel(), 1).reshape(-1, _GX.size, 2)
        return np.asarray((np.linalg.norm(d1, axis=-1) * width) @ _GW, dtype=np.float64)

    def parameter(self, u: FloatArray) -> FloatArray:
        """Curve parameter ``tau`` at arc length ``u`` (Newton from the table, safeguarded)."""
        u = np.clip(np.asarray(u, dtype=np.float64).ravel(), 0.0, self.length)
        j = np.clip(np.searchsorted(self._arc, u, side="right") - 1, 0, self._tau.size - 2)
        lo, hi = self._tau[j], self._tau[j + 1]
        span = np.maximum(self._arc[j + 1] - self._arc[j], 1e-300)
        tau = lo + (hi - lo) * (u - self._arc[j]) / span
        for _ in range(50):
            f = self._arc[j] + self._speed_integral(lo, tau) - u
            speed = np.linalg.norm(self.curve(tau, 1), axis=-1)
            step = f / np.maximum(speed, 1e-300)
            tau = np.clip(tau - step, lo, hi)
            if np.all(np.abs(f) <= 1e-13 * max(self.length, 1.0)):
                break
        return tau

    def point(self, u: FloatArray) -> FloatArray:
        """Positions at arc lengths ``u`` [m]."""
        u = np.asarray(u, dtype=np.float64)
        return self.curve(self.parameter(u), 0).reshape(*u.shape, 2)

    def heading(self, u: FloatArray) -> FloatArray:
        """Direction of ``r'(τ)`` [rad]."""
        u = np.asarray(u, dtype=np.float64)
        d1 = self.curve(self.parameter(u), 1)
        return np.arctan2(d1[:, 1], d1[:, 0]).reshape(u.shape)

    def curvature(self, u: FloatArray) -> FloatArray:
        """``(x'y'' - y'x'') / |r'|³`` [1/m]."""
        u = np.asarray(u, dtype=np.float64)
        tau = self.parameter(u)
        d1, d2 = self.curve(tau, 1), self.curve(tau, 2)
        cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
        out: FloatArray = (cross / np.linalg.norm(d1, axis=-1) ** 3).reshape(u.shape)
        return out


@dataclass(frozen=True)
class ReversedPiece(Piece):
    """``piece`` travelled backwards: heading + π, curvature negated."""

    piece: Piece

    @property
    def length(self) -> float:  # type: ignore[override]
        """Length of the underlying piece [m]."""
        return self.piece.length

    def _mirror(self, u: FloatArray) -> FloatArray:
        out: FloatArray = self.piece.length - np.asarray(u, dtype=np.float64)
        return out

    def point(self, u: FloatArray) -> FloatArray:
        """Positions, travelled backwards [m]."""
        return self.piece.point(self._mirror(u))

    def heading(self, u: FloatArray) -> FloatArray:
        """Headings turned by π [rad]."""
        out: FloatArray = self.piece.heading(self._mirror(u)) + np.pi
        return out

    def curvature(self, u: FloatArray) -> FloatArray:
        """Curvatures with the opposite sign [1/m]."""
        out: FloatArray = -self.piece.curvature(self._mirror(u))
        return out

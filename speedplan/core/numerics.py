"""Numerics shared by the layers, one definition each: quadrature rules, angle wrapping."""

from __future__ import annotations

from typing import Any

import numpy as np

from .checks import FloatArray

__all__ = ["GAUSS_NODES", "GAUSS_WEIGHTS", "SHORT_NODES", "SHORT_WEIGHTS", "gauss_legendre",
           "wrap_angle", "wrap_heading"]


def gauss_legendre(points: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of the ``points``-point Gauss–Legendre rule on ``[0, 1]``.

    Exact for polynomials of degree ``2 points - 1``.

    Examples
    --------
    >>> x, w = gauss_legendre(2)
    >>> round(float(w @ x**3), 15)
    0.25
    """
    x, w = np.polynomial.legendre.leggauss(points)
    return 0.5 * (x + 1.0), 0.5 * w


#: 16-point rule on [0, 1]: exact for polynomials of degree 31.
GAUSS_NODES, GAUSS_WEIGHTS = gauss_legendre(16)
#: 4-point rule on [0, 1] (degree 7), for short spans.
SHORT_NODES, SHORT_WEIGHTS = gauss_legendre(4)


def wrap_angle(theta: Any) -> FloatArray:
    """Angles [rad] wrapped into ``[-π, π)`` by ``(θ + π) mod 2π - π`` (for angle differences).

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.core.numerics import wrap_angle
    >>> wrap_angle([0.5, 1.5 * np.pi, -3.5 * np.pi]).round(12).tolist()
    [0.5, -1.570796326795, 1.570796326795]
    """
    out: FloatArray = (np.asarray(theta, dtype=np.float64) + np.pi) % (2.0 * np.pi) - np.pi
    return out


def wrap_heading(theta: Any) -> FloatArray:
    """Angles [rad] wrapped to ``[-π, π)``; values already in that range are returned unchanged.

    The exported ``heading`` column: a heading the law computed in range keeps its last bits.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.core.numerics import wrap_heading
    >>> wrap_heading([0.5, np.pi, 1.5 * np.pi, -np.pi]).round(12).tolist()
    [0.5, -3.14159265359, -1.570796326795, -3.14159265359]
    """
    th = np.asarray(theta, dtype=np.float64)
    wrapped = np.where((th >= -np.pi) & (th < np.pi), th, wrap_angle(th))
    # Rounding can bring a wrapped value up to π itself.
    out: FloatArray = np.where(wrapped >= np.pi, -np.pi, wrapped)
    return out

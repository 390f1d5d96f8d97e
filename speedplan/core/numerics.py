"""Quadrature rules shared by the geometry and timing layers (one definition each)."""

from __future__ import annotations

import numpy as np

__all__ = ["GAUSS_NODES", "GAUSS_WEIGHTS", "SHORT_NODES", "SHORT_WEIGHTS", "gauss_legendre"]


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

"""NURBS curves as in a VDA 5050 edge ``trajectory`` (degree, knotVector, controlPoints)."""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.interpolate import BSpline

from .._checks import FloatArray, as_array
from ..errors import InvalidInputError
from .pieces import CurvePiece

__all__ = ["nurbs_piece"]


def nurbs_piece(degree: int, knots: Any, control_points: Any, weights: Any = None) -> CurvePiece:
    """Arc-length parametrised piece of the NURBS curve.

    Evaluated as a B-spline in homogeneous coordinates ``(w x, w y, w)`` (``scipy.interpolate
    .BSpline``), divided through by ``w``; derivatives by the quotient rule.

    Parameters
    ----------
    degree : int
        Polynomial degree (>= 1).
    knots : array_like
        Non-decreasing knot vector of length ``len(control_points) + degree + 1``.
    control_points : array_like, shape (m, 2)
        Control points [m].
    weights : array_like, shape (m,), optional
        Positive weights (default all 1: a plain B-spline).
    """
    if isinstance(degree, bool) or int(degree) != degree or degree < 1:
        raise InvalidInputError(f"`degree` must be an integer >= 1; got {degree!r}")
    k = int(degree)
    ctrl = as_array("control_points", control_points)
    if ctrl.ndim != 2 or ctrl.shape[1] != 2 or ctrl.shape[0] < k + 1:
        raise InvalidInputError(
            f"`control_points` must have shape (m, 2) with m >= degree + 1 = {k + 1}; "
            f"got {ctrl.shape}"
        )
    m = ctrl.shape[0]
    t = as_array("knots", knots, ndim=1, length=m + k + 1)
    if (np.diff(t) < 0).any():
        raise InvalidInputError("`knots` must be non-decreasing")
    w = np.ones(m) if weights is None else as_array("weights", weights, ndim=1, length=m)
    if not (w > 0).all():
        raise InvalidInputError("`weights` must all be > 0")
    lo, hi = t[k], t[m]
    if not hi > lo:
        raise InvalidInputError("`knots` span an empty parameter range")
    spline = BSpline(t, np.column_stack((ctrl * w[:, None], w)), k)
    derivs = [spline] + [spline.derivative(i) for i in (1, 2)]

    def curve(tau: FloatArray, nu: int) -> FloatArray:
        tau = np.clip(np.asarray(tau, dtype=np.float64).ravel(), lo, hi)
        h0 = derivs[0](tau)
        p, wt = h0[:, :2], h0[:, 2:3]
        r = p / wt
        if nu == 0:
            return np.asarray(r, dtype=np.float64)
        h1 = derivs[1](tau)
        dp, dw = h1[:, :2], h1[:, 2:3]
        r1 = (dp - r * dw) / wt
        if nu == 1:
            return np.asarray(r1, dtype=np.float64)
        h2 = derivs[2](tau)
        d2p, d2w = h2[:, :2], h2[:, 2:3]
        out: FloatArray = (d2p - 2 * r1 * dw - r * d2w) / wt
        return out

    breaks = np.unique(t[k : m + 1])
    piece = CurvePiece(curve, breaks)
    if not piece.length > 0:
        raise InvalidInputError("the NURBS curve has zero length")
    return piece

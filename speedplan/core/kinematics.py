"""Kinematics of motion along a path, from the speed law ``w(s) = v²`` and the curvature.

One evaluator for every layer that needs these quantities: the model's lateral-jerk rows,
`speedplan.timing.verify` and `SpeedProfile.at`. The functions are pure numpy and
broadcast over their arguments. Symbols (SI units): arc length ``s`` [m], squared speed
``w`` [m²/s²], speed ``v = sqrt(w)`` [m/s], ``w' = dw/ds`` [m/s²], tangential acceleration
``a = w'/2`` [m/s²], jerk ``j = da/dt`` [m/s³], curvature ``κ`` [1/m] and its rate
``κ' = dκ/ds`` [1/m²], which callers take from the path's exact derivative
(`speedplan.Path.curvature_rate`).

Lateral quantities follow from ``a_lat = κ v² = κ w``: ``d a_lat/ds = κ' w + κ w'`` and,
with ``ds/dt = v``, the lateral jerk ``j_lat = v (κ' w + 2 κ a)``; the yaw rate is ``κ v``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .checks import FloatArray

__all__ = ["acceleration", "friction_ellipse", "lateral_acceleration",
           "lateral_acceleration_rate", "lateral_jerk", "lateral_jerk_from_slope",
           "lateral_rate_weights", "speed", "yaw_rate"]


def speed(w: Any) -> FloatArray:
    """Speed ``v = sqrt(w)`` [m/s] from the squared speed ``w`` [m²/s²] (negative ``w``: 0).

    Examples
    --------
    >>> import numpy as np
    >>> speed(np.array([4.0, 0.0, -1e-18])).tolist()
    [2.0, 0.0, 0.0]
    """
    out: FloatArray = np.sqrt(np.maximum(np.asarray(w, dtype=np.float64), 0.0))
    return out


def acceleration(w_slope: Any) -> FloatArray:
    """Tangential acceleration ``a = w'/2`` [m/s²] from ``w' = dw/ds`` [m/s²].

    ``d(v²)/ds = 2 v dv/ds = 2 dv/dt``.

    Examples
    --------
    >>> import numpy as np
    >>> acceleration(np.array([2.0, -1.0])).tolist()
    [1.0, -0.5]
    """
    out: FloatArray = 0.5 * np.asarray(w_slope, dtype=np.float64)
    return out


def lateral_acceleration(kappa: Any, w: Any) -> FloatArray:
    """Lateral (centripetal) acceleration ``κ w = κ v²`` [m/s²], signed like ``κ``.

    Parameters
    ----------
    kappa : array_like
        Curvature [1/m].
    w : array_like
        Squared speed [m²/s²].

    Examples
    --------
    On an arc of radius 4 m at 2 m/s, ``v² / R = 1`` m/s²:

    >>> import numpy as np
    >>> lateral_acceleration(np.array([0.25, -0.25]), 4.0).tolist()
    [1.0, -1.0]
    """
    out: FloatArray = np.asarray(kappa, dtype=np.float64) * w
    return out


def yaw_rate(kappa: Any, v: Any) -> FloatArray:
    """Yaw rate ``κ v`` [rad/s] of the direction of travel, signed like ``κ``.

    Parameters
    ----------
    kappa : array_like
        Curvature [1/m].
    v : array_like
        Speed [m/s].

    Examples
    --------
    On an arc of radius 4 m at 2 m/s, ``v / R = 0.5`` rad/s:

    >>> yaw_rate(0.25, 2.0).tolist()
    0.5
    """
    out: FloatArray = np.asarray(kappa, dtype=np.float64) * v
    return out


def lateral_acceleration_rate(kappa: Any, kappa_rate: Any, w: Any, w_slope: Any) -> FloatArray:
    """``d(κ w)/ds = κ' w + κ w'`` [1/s²]: the lateral acceleration's change per metre.

    Times the speed it is the lateral jerk (`lateral_jerk`); linear in ``w`` and ``w'``,
    it is what the discrete problem's lateral-jerk rows hold at nodes and cell midpoints.

    Parameters
    ----------
    kappa, kappa_rate : array_like
        Curvature [1/m] and its rate ``dκ/ds`` [1/m²].
    w, w_slope : array_like
        Squared speed [m²/s²] and its slope ``dw/ds`` [m/s²].

    Examples
    --------
    A clothoid ``κ = 0.1 s`` at constant speed ``w = 4``: ``κ' w = 0.4``.

    >>> lateral_acceleration_rate(0.3, 0.1, 4.0, 0.0).tolist()
    0.4
    """
    out: FloatArray = np.asarray(kappa_rate, dtype=np.float64) * w + np.multiply(kappa,
                                                                                 w_slope)
    return out


def lateral_rate_weights(kappa: Any, kappa_rate: Any, value_weights: Any,
                         slope_weights: Any) -> FloatArray:
    """Weights on the nodes' ``w`` of ``κ' w + κ w'`` at points where both are linear in them.

    A discretisation gives ``w`` and ``w'`` at a point as weighted sums of node values
    (``value_weights``, ``slope_weights``, the last axis over the nodes); the lateral
    acceleration's rate (`lateral_acceleration_rate`) is then ``weights @ w_nodes``, what
    a lateral-jerk row bounds times ``sqrt(w)``.

    Parameters
    ----------
    kappa, kappa_rate : array_like, shape (k,)
        Curvature [1/m] and its rate [1/m²] at the ``k`` points.
    value_weights, slope_weights : array_like, shape (k, p) or (p,)
        Weights of ``p`` nodes giving ``w`` (dimensionless) and ``w'`` [1/m] at each point.

    Examples
    --------
    At a cell's midpoint, ``w = (w_0 + w_1) / 2`` and ``w' = (w_1 - w_0) / h``, ``h = 0.5``:

    >>> import numpy as np
    >>> lateral_rate_weights(np.array([0.25]), np.array([0.5]), [0.5, 0.5], [-2.0, 2.0]).tolist()
    [[-0.25, 0.75]]
    """
    out: FloatArray = (np.asarray(kappa_rate, dtype=np.float64)[..., None] * value_weights
                       + np.asarray(kappa, dtype=np.float64)[..., None] * slope_weights)
    return out


def lateral_jerk_from_slope(kappa: Any, kappa_rate: Any, w: Any, w_slope: Any) -> FloatArray:
    """Lateral jerk ``sqrt(w) (κ' w + κ w')`` [m/s³] from ``w`` and its slope ``w' = dw/ds``.

    `lateral_jerk` with ``a = w'/2``: the form of the discrete problem, where ``w'`` is a
    difference of node values.

    Parameters
    ----------
    kappa, kappa_rate : array_like
        Curvature [1/m] and its rate ``dκ/ds`` [1/m²].
    w, w_slope : array_like
        Squared speed [m²/s²] and its slope ``dw/ds`` [m/s²].

    Examples
    --------
    A clothoid ``κ = 0.1 s`` at a constant 2 m/s: ``c v³ = 0.8`` m/s³.

    >>> lateral_jerk_from_slope(0.3, 0.1, 4.0, 0.0).tolist()
    0.8
    """
    out: FloatArray = speed(w) * lateral_acceleration_rate(kappa, kappa_rate, w, w_slope)
    return out


def lateral_jerk(kappa: Any, kappa_rate: Any, w: Any, a: Any, v: Any = None) -> FloatArray:
    """Lateral jerk ``d(κ v²)/dt = v (κ' w + 2 κ a)`` [m/s³], signed like ``a_lat``'s change.

    Parameters
    ----------
    kappa, kappa_rate : array_like
        Curvature [1/m] and its rate ``dκ/ds`` [1/m²] (the path's exact derivative).
    w : array_like
        Squared speed [m²/s²].
    a : array_like
        Tangential acceleration [m/s²].
    v : array_like, optional
        Speed [m/s], when the caller has it (the law's own); default ``sqrt(w)``.

    Examples
    --------
    A clothoid ``κ = c s`` (``c = 0.1`` 1/m²) at a constant 2 m/s: ``c v³ = 0.8`` m/s³.

    >>> lateral_jerk(0.3, 0.1, 4.0, 0.0).tolist()
    0.8

    On an arc (``κ' = 0``) of radius 4 m, braking at 1 m/s² from 2 m/s: ``2 v κ a = -1``.

    >>> lateral_jerk(0.25, 0.0, 4.0, -1.0).tolist()
    -1.0
    """
    speed_ = speed(w) if v is None else v
    out: FloatArray = np.multiply(speed_, np.asarray(kappa_rate, dtype=np.float64) * w
                                  + 2.0 * np.asarray(kappa, dtype=np.float64) * a)
    return out


def friction_ellipse(a: Any, a_lat: Any, a_max: float, a_decel: float,
                     a_lat_max: float) -> FloatArray:
    """The friction ellipse's radius ``sqrt((a / A)² + (a_lat / a_lat_max)²)``, 1 on it.

    ``A`` is ``a_max`` where the vehicle accelerates (``a >= 0``) and ``a_decel`` where it
    brakes.

    Parameters
    ----------
    a, a_lat : array_like
        Tangential and lateral acceleration [m/s²].
    a_max, a_decel, a_lat_max : float
        Acceleration, braking and lateral limits [m/s²], > 0.

    Examples
    --------
    >>> import numpy as np
    >>> friction_ellipse(np.array([0.6, -1.0]), np.array([0.8, 0.0]), 1.0, 2.0, 1.0).tolist()
    [1.0, 0.5]
    """
    a = np.asarray(a, dtype=np.float64)
    out: FloatArray = np.hypot(a / np.where(a >= 0.0, a_max, a_decel),
                               np.asarray(a_lat, dtype=np.float64) / a_lat_max)
    return out

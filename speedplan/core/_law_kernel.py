"""Compiled quadrature, time inversion and kinematics of `TimeLaw`.

Plain arrays in, plain arrays out (the law's chain of quadratic pieces in ``w`` or
``u = w^{3/4}``); it lives in ``core`` next to `speedplan.core.jit`, which compiles it
(the ``"time law"`` family) without the core layer importing the timing layer.

The time inversion: on a ``w``-piece moving at both ends whose time the quadrature gets to
rounding (``TimeLaw._exact_inverse``), the offset reached at time ``τ`` is the exact solution
of ``dσ/dτ = sqrt(w(σ))`` from the knot nearer in time (`_moving_offset`); it meets
the quadrature's time to the same ``1e-15`` of the piece's time as the iteration does, at a
fifth of its cost (the 10 000 samples of a 100 Hz trajectory: 0.6 ms against 3.3 ms).
Other pieces (in ``u``, at a standstill, or where the rule is off) run a safeguarded Newton
iteration on one 16-point Gauss–Legendre integral (stopping at ``|t(σ) - τ| <= 1e-15`` of
the piece's time), started from the third-order kinematic expansion at the left knot
(``σ ≈ v τ + a τ²/2 + j τ³/6``) or, at a standstill, the piece's own power law. Results
agree with the numpy formulation to rounding (sampled states within 2e-15 of their scale on
every sample path). Used by
`speedplan.timing.law` once numba is loaded (before that, the same formulas in numpy:
``speedplan.timing._law_numpy``): ``import speedplan`` stays free of numba. The entry points'
explicit signatures are in `signatures`; `speedplan.core.jit` loads them from
numba's cache (~20 ms with numba's runtime loaded) or compiles them (1.5-5 s, once per
installation).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .checks import FloatArray, IntArray
from .jit import inner, kernel, tolerate_stale_indexes
from .numerics import GAUSS_NODES, GAUSS_WEIGHTS

tolerate_stale_indexes()  # before any kernel below is loaded from the cache

__all__ = ["integrals", "invert", "kinematics"]

BoolArray = np.ndarray

#: Gauss nodes and weights on [0, 1], then the nodes of the substitutions ``σ = τ²`` and
#: ``σ = τ³`` and their Jacobians (rows: nodes, weights, τ², 2τ, τ³, 3τ²): no ``pow`` inside.
_RULE = np.ascontiguousarray(np.stack((
    GAUSS_NODES, GAUSS_WEIGHTS, GAUSS_NODES**2, 2.0 * GAUSS_NODES, GAUSS_NODES**3,
    3.0 * GAUSS_NODES**2)), dtype=np.float64)

#: The law's piece arrays as one argument (``x, y, g, c, is_u, y_right, g_right``, see
#: `_arrays`).
_PIECES = "Tuple((f8[::1], f8[::1], f8[::1], f8[::1], b1[::1], f8[::1], f8[::1]))"
Pieces = tuple[FloatArray, FloatArray, FloatArray, FloatArray, np.ndarray, FloatArray,
               FloatArray]


@inner
def _speed(pieces: Pieces, j: int, dx: float, dr: float) -> float:
    """``v`` at offsets ``(dx, dr)`` of piece ``j``: ``TimeLaw._speed`` for one point."""
    _x, y, g, c, is_u, y_right, g_right = pieces
    cj = c[j]
    if dx > dr:  # from the nearer knot
        val = y_right[j] - g_right[j] * dr + 0.5 * cj * dr * dr
    else:
        val = y[j] + g[j] * dx + 0.5 * cj * dx * dx
    val = max(val, 0.0)
    if is_u[j]:
        val = val * np.cbrt(val)
    return math.sqrt(val)


@inner
def _state(pieces: Pieces, j: int, dx: float, dr: float) -> tuple[float, float, float, float]:
    """``w, v, a, jerk`` at offsets ``(dx, dr)`` of piece ``j``.

    ``y, y', y''`` from the nearer knot (accurate relative to its own size next to a
    standstill), then ``w = y`` or ``u^{4/3}``, ``v = sqrt(w)``, ``a = y'/2`` or
    ``(2/3) u^{1/3} u'``, jerk ``y'' v / 2`` or ``(2/9) u'² + (2/3) u u''``.
    """
    _x, y, g, c, is_u, y_right, g_right = pieces
    cj = c[j]
    if dx > dr:
        val = y_right[j] - g_right[j] * dr + 0.5 * cj * dr * dr
        dy = g_right[j] - cj * dr
    else:
        val = y[j] + g[j] * dx + 0.5 * cj * dx * dx
        dy = g[j] + cj * dx
    val = max(val, 0.0)
    if is_u[j]:
        cube = np.cbrt(val)
        w = val * cube
        v = math.sqrt(w)
        return w, v, (2.0 / 3.0) * cube * dy, (2.0 / 9.0) * dy * dy + (2.0 / 3.0) * val * cj
    v = math.sqrt(val)
    return val, v, 0.5 * dy, 0.5 * cj * v


@inner
def _integral(pieces: Pieces, j: int, lo: float, hi: float, right: bool,
              rule: FloatArray) -> float:
    """``TimeLaw._integral`` for one stretch ``[lo, hi]`` of piece ``j``."""
    x, y, g, c, is_u, y_right, g_right = pieces
    width = x[j + 1] - x[j]
    at_rest = (y_right[j] <= 0.0 if right else y[j] <= 0.0) and lo <= 0.0
    row = 4 if is_u[j] else 2  # the substitution's nodes and Jacobians
    span = hi - lo
    total = 0.0
    if not at_rest and not is_u[j]:  # the common case, with the piece's data in registers
        if not span > 0:
            return 0.0
        y0, g0, c0, y1, g1 = y[j], g[j], c[j], y_right[j], g_right[j]
        for i in range(rule.shape[1]):
            off = lo + span * rule[0, i]
            if right:
                dx, dr = width - off, off
            else:
                dx, dr = off, width - off
            # Both ends' forms, then the nearer one (as _speed): no branch in the loop body.
            from_left = y0 + g0 * dx + 0.5 * c0 * dx * dx
            from_right = y1 - g1 * dr + 0.5 * c0 * dr * dr
            val = max(from_right if dx > dr else from_left, 0.0)
            total += rule[1, i] * (span / math.sqrt(val))
        return total
    for i in range(rule.shape[1]):
        if at_rest:
            off = span * rule[row, i]
            jac = span * rule[row + 1, i]
        else:
            off = lo + span * rule[0, i]
            jac = span
        if right:
            dx, dr = width - off, off
        else:
            dx, dr = off, width - off
        v = _speed(pieces, j, dx, dr)
        total += rule[1, i] * (jac / v if jac > 0 else 0.0)
    return total


@kernel
def _integrals_into(pieces: Pieces, j: IntArray, lo: FloatArray, hi: FloatArray,
                    right: BoolArray, rule: FloatArray, out: FloatArray) -> None:
    for k in range(j.size):
        out[k] = _integral(pieces, j[k], lo[k], hi[k], right[k], rule)


def integrals(pieces: Any, j: np.ndarray, lo: np.ndarray, hi: np.ndarray,
              right: np.ndarray) -> np.ndarray:
    """``∫ ds / v`` over offsets ``[lo, hi]`` of pieces ``j`` (see ``TimeLaw._integral``)."""
    j, lo, hi, right = np.broadcast_arrays(j, lo, hi, right)
    out = np.empty(j.shape)
    _integrals_into(_arrays(pieces), _flat(j, np.int64), _flat(lo, np.float64),
                    _flat(hi, np.float64), _flat(right, np.bool_), _RULE, out.reshape(-1))
    return out


@inner
def _step_settles(e: float, v: float, acc: float, jerk: float, ttol: float,
                  width: float) -> bool:
    """Whether a Newton step of length ``e`` [m] lands within the time tolerance ``ttol``.

    Newton's error after the step, for the offset error ``e``, is ``|t''/2t'| e² +
    |t'''/3t'| e³`` to leading orders, with ``t' = 1/v``, ``t'' = -a/v³`` and ``t''' = -j/v⁴
    + 3a²/v⁵`` the derivatives of the time in the offset. Ten times that, in time, below a
    quarter of the tolerance, and a step under 1e-3 of the piece: the integral that would
    confirm the step (half the cost of a typical sample) is skipped.
    """
    if not (v > 0.0 and e <= 1e-3 * width):
        return False
    v2 = v * v
    err = e * e * (0.5 * abs(acc) / v2 + e * (abs(jerk) / (v2 * v) + 3.0 * acc * acc
                                               / (v2 * v2)) / 3.0)
    return 10.0 * err <= 0.25 * ttol * v


@inner
def _moving_offset(tau: float, y0: float, g0: float, c0: float) -> float:
    """Offset reached at time ``tau`` from a knot where ``w = y0 > 0``: the exact solution.

    ``w = y0 + g0 σ + c0 σ²/2`` makes ``dσ/dτ = sqrt(w)`` solvable (``σ'' = g0/2 + c0 σ/2``):
    with ``k = sqrt(|c0|/2)``, ``σ(τ) = v0 τ S(kτ) + (g0 τ²/4) S(kτ/2)²``, ``S(z) = sinh(z)/z``
    for ``c0 > 0``, ``sin(z)/z`` for ``c0 < 0`` and 1 for ``c0 = 0``. Written with ``S``,
    neither term cancels as ``c0 → 0`` (the ``cosh(kτ) - 1`` of the textbook form does).
    Valid while ``w > 0`` on the way. From a right knot (time running backwards) pass
    ``y_right`` and ``-g_right``.
    """
    half = 0.5 * tau * math.sqrt(0.5 * abs(c0))
    if half == 0.0:
        s_full, s_half = 1.0, 1.0
    elif c0 > 0.0:
        s_full, s_half = math.sinh(2.0 * half) / (2.0 * half), math.sinh(half) / half
    else:
        s_full, s_half = math.sin(2.0 * half) / (2.0 * half), math.sin(half) / half
    return math.sqrt(y0) * tau * s_full + 0.25 * g0 * tau * tau * s_half * s_half


@kernel
def _invert_into(pieces: Pieces, T: FloatArray, j: IntArray, t: FloatArray, rule: FloatArray,
                 exact: BoolArray, dx_out: FloatArray, dr_out: FloatArray) -> None:
    """Offsets reached at times ``t`` in pieces ``j`` (``TimeLaw._invert``).

    Closed form on the pieces flagged ``exact``, from the knot nearer in time (its own
    ``y, g``: the form the quadrature uses there); elsewhere the iteration.
    """
    x, y, g, c, is_u, y_right, g_right = pieces
    for k in range(t.size):
        jk = j[k]
        width = x[jk + 1] - x[jk]
        span_t = T[jk + 1] - T[jk]
        if exact[jk]:
            tau = t[k] - T[jk]
            if tau >= span_t:
                dx_out[k], dr_out[k] = width, 0.0
            elif tau <= 0:
                dx_out[k], dr_out[k] = 0.0, width
            elif tau <= 0.5 * span_t:
                off = min(max(_moving_offset(tau, y[jk], g[jk], c[jk]), 0.0), width)
                dx_out[k], dr_out[k] = off, width - off
            else:
                back = T[jk + 1] - t[k]
                off = min(max(_moving_offset(back, y_right[jk], -g_right[jk], c[jk]), 0.0),
                          width)
                dx_out[k], dr_out[k] = width - off, off
            continue
        rest_left = y[jk] <= 0.0
        rest_right = (y_right[jk] <= 0.0) and not rest_left
        # A moving w-piece gets here only where the rule is off (``w`` varies by orders of
        # magnitude on it): the local error model of ``_step_settles`` does not hold there.
        skip_confirm = rest_left or rest_right or is_u[jk]
        power = 3.0 if is_u[jk] else 2.0
        tau = T[jk + 1] - t[k] if rest_right else t[k] - T[jk]
        frac = tau / span_t if span_t > 0 else 0.0
        frac = min(max(frac, 0.0), 1.0)
        if rest_left or rest_right:  # the piece's own power law
            off = width * frac**power
        else:  # third order in time from the left knot: one or two Newton steps remain
            y0, g0, c0 = y[jk], g[jk], c[jk]
            if is_u[jk]:
                cube = np.cbrt(y0)
                v0 = math.sqrt(y0 * cube)
                a0 = (2.0 / 3.0) * cube * g0
                j0 = (2.0 / 9.0) * g0 * g0 + (2.0 / 3.0) * y0 * c0
            else:
                v0 = math.sqrt(y0)
                a0 = 0.5 * g0
                j0 = 0.5 * c0 * v0
            off = tau * (v0 + tau * (0.5 * a0 + tau * j0 / 6.0))
            if not (off > 0.0 and off < width):
                off = width * frac
        lo, hi = 0.0, width
        ttol = 1e-15 * max(span_t, 1e-300)
        if tau > 0 and tau < span_t:  # at a knot the offset is exact
            for _ in range(100):
                part = _integral(pieces, jk, 0.0 * off, off, rest_right, rule)
                f = part - tau  # increasing in the offset
                if f <= 0:
                    lo = off
                if f >= 0:
                    hi = off
                if rest_right:
                    _w, v, acc, jerk = _state(pieces, jk, width - off, off)
                else:
                    _w, v, acc, jerk = _state(pieces, jk, off, width - off)
                step = f * v
                newton = off - step
                converged = abs(f) <= ttol
                if converged:
                    new = off
                elif newton >= lo and newton <= hi:
                    new = newton
                    if skip_confirm and _step_settles(abs(step), v, acc, jerk, ttol, width):
                        off = new
                        break
                else:
                    new = 0.5 * (lo + hi)
                moving = not converged and abs(new - off) > 4e-16 * max(abs(new), 1e-300)
                off = new
                if not moving:
                    break
        if tau >= span_t:
            off = width
        elif tau <= 0:
            off = 0.0
        if rest_right:
            dx_out[k], dr_out[k] = width - off, off
        else:
            dx_out[k], dr_out[k] = off, width - off


def invert(pieces: Any, T: np.ndarray, j: np.ndarray, t: np.ndarray, exact: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray]:
    """Offsets ``(dx, dr)`` from the left and right knots of pieces ``j`` at times ``t``.

    ``exact``: per piece, whether to take the closed form (``TimeLaw._exact_inverse``).
    """
    dx, dr = np.empty(t.shape), np.empty(t.shape)
    _invert_into(_arrays(pieces), _flat(T, np.float64), _flat(j, np.int64),
                 _flat(t, np.float64), _RULE, _flat(exact, np.bool_), dx.reshape(-1),
                 dr.reshape(-1))
    return dx, dr


@kernel
def _kinematics_into(pieces: Pieces, j: IntArray, dx: FloatArray, dr: FloatArray,
                     w_out: FloatArray, v_out: FloatArray, a_out: FloatArray,
                     jerk_out: FloatArray) -> None:
    """``w, v, a, jerk`` at offsets ``(dx, dr)`` of pieces ``j`` (`_state`)."""
    for k in range(j.size):
        w_out[k], v_out[k], a_out[k], jerk_out[k] = _state(pieces, j[k], dx[k], dr[k])


def kinematics(pieces: Any, j: np.ndarray, dx: np.ndarray, dr: np.ndarray
               ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """``w, v, a, jerk`` at offsets ``(dx, dr)`` of pieces ``j`` (broadcast together)."""
    j, dx, dr = np.broadcast_arrays(j, dx, dr)
    out = tuple(np.empty(j.shape) for _ in range(4))
    _kinematics_into(_arrays(pieces), _flat(j, np.int64), _flat(dx, np.float64),
                     _flat(dr, np.float64), out[0].reshape(-1), out[1].reshape(-1),
                     out[2].reshape(-1), out[3].reshape(-1))
    return out[0], out[1], out[2], out[3]


def _flat(a: np.ndarray, dtype: type) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(a, dtype=dtype).reshape(-1))


def _arrays(p: Any) -> Pieces:
    """The piece arrays of a ``TimeLaw._pieces``, contiguous as the signatures require."""
    return (np.ascontiguousarray(p.x), np.ascontiguousarray(p.y), np.ascontiguousarray(p.g),
            np.ascontiguousarray(p.c), np.ascontiguousarray(p.is_u),
            np.ascontiguousarray(p.y_right), np.ascontiguousarray(p.g_right))


#: The kernels called from Python (the others are called only from compiled code).
ENTRY_POINTS = ("_integrals_into", "_invert_into", "_kinematics_into")


def signatures() -> dict[str, str]:
    """Every kernel and its one signature, each after the kernels it calls.

    `speedplan.core.jit` compiles them in this order and then refuses other types.
    """
    at = f"({_PIECES}, i8, f8, f8)"
    return {
        "_speed": f"f8{at}",
        "_state": f"UniTuple(f8, 4){at}",
        "_integral": f"f8({_PIECES}, i8, f8, f8, b1, f8[:, ::1])",
        "_step_settles": "b1(f8, f8, f8, f8, f8, f8)",
        "_moving_offset": "f8(f8, f8, f8, f8)",
        "_integrals_into":
            f"void({_PIECES}, i8[::1], f8[::1], f8[::1], b1[::1], f8[:, ::1], f8[::1])",
        "_invert_into":
            f"void({_PIECES}, f8[::1], i8[::1], f8[::1], f8[:, ::1], b1[::1], f8[::1], f8[::1])",
        "_kinematics_into":
            f"void({_PIECES}, i8[::1], f8[::1], f8[::1], f8[::1], f8[::1], f8[::1], f8[::1])",
    }

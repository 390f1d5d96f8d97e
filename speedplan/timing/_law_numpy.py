"""The time law's quadrature, inversion and kinematics in numpy.

The interface of `speedplan.core._law_kernel`, the compiled version.

Used until numba's compiled code can run without compiling (`backend`): the first
``plan()`` of a fresh environment answers with Clarabel while a background process compiles
the banded kernel, and compiling the time-law kernel in the foreground too would cost it
seconds. The two agree to rounding (``tests/timing/test_time_law.py``
compares them); durations and sampled states differ by a few units in the last place.
"""

from __future__ import annotations

from types import ModuleType
from typing import Any

import numpy as np

from ..core.checks import FloatArray, IntArray
from ..core.numerics import GAUSS_NODES, GAUSS_WEIGHTS

__all__ = ["backend", "integrals", "invert", "kinematics"]


def backend() -> ModuleType:
    """The compiled kernel when it runs without compiling in this process, else this module.

    Only once numba is loaded for the relaxation's kernel (a process that plans only without
    jerk never loads it); then the time law's kernel loads from numba's cache in ~20 ms, or
    a background process compiles it (`speedplan.core.jit`, family ``"time law"``) and
    numpy answers meanwhile.
    """
    from ..core.jit import FAMILIES

    if FAMILIES["relaxation"].module is not None:
        law = FAMILIES["time law"].available(wait=False)
        if law is not None:
            return law
    import sys

    return sys.modules[__name__]


def _y_only(p: Any, j: IntArray, dx: FloatArray, dr: FloatArray
            ) -> tuple[FloatArray, np.ndarray, FloatArray]:
    """``y`` from the nearer knot (with the side it was evaluated from and ``y''``)."""
    cj = p.c[j]
    right = dx > dr
    y = np.where(right, p.y_right[j] - p.g_right[j] * dr + 0.5 * cj * dr * dr,
                 p.y[j] + p.g[j] * dx + 0.5 * cj * dx * dx)
    return np.maximum(y, 0.0), right, cj


def _speed(p: Any, j: IntArray, dx: FloatArray, dr: FloatArray) -> FloatArray:
    """``v`` alone at offsets ``(dx, dr)`` of pieces ``j`` (``j`` may broadcast)."""
    y = _y_only(p, j, dx, dr)[0]
    v: FloatArray = np.sqrt(np.where(p.is_u[j], y * np.cbrt(y), y))
    return v


def kinematics(p: Any, j: IntArray, dx: FloatArray, dr: FloatArray
               ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """``w, v, a, jerk`` at offsets ``(dx, dr)`` of pieces ``j`` (broadcast together)."""
    y, right, ddy = _y_only(p, j, dx, dr)
    dy = np.where(right, p.g_right[j] - ddy * dr, p.g[j] + ddy * dx)
    is_u = p.is_u[j]
    cube = np.cbrt(y)
    w = np.where(is_u, y * cube, y)
    v = np.sqrt(w)
    a = np.where(is_u, (2.0 / 3.0) * cube * dy, 0.5 * dy)
    jerk = np.where(is_u, (2.0 / 9.0) * dy * dy + (2.0 / 3.0) * y * ddy, 0.5 * ddy * v)
    shape = np.broadcast_shapes(np.shape(j), np.shape(dx), np.shape(dr))
    return (np.broadcast_to(w, shape), np.broadcast_to(v, shape), np.broadcast_to(a, shape),
            np.broadcast_to(jerk, shape))


def integrals(p: Any, j: IntArray, lo: FloatArray, hi: FloatArray,
              right: np.ndarray) -> FloatArray:
    """``∫ ds / v`` over offsets ``[lo, hi]`` of pieces ``j`` (see ``TimeLaw._integral``)."""
    width = p.x[j + 1] - p.x[j]
    at_rest = np.where(right, p.y_right[j] <= 0.0, p.y[j] <= 0.0) & (lo <= 0.0)
    power = np.where(p.is_u[j], 3.0, 2.0)
    span = hi - lo
    t = GAUSS_NODES[:, None]
    tw = GAUSS_WEIGHTS[:, None]
    off = np.where(at_rest, span * t**power, lo + span * t)  # from the anchoring knot
    jac = np.where(at_rest, span * power * t ** (power - 1.0), span)
    dx = np.where(right, width - off, off)
    dr = np.where(right, off, width - off)
    v = _speed(p, j, dx, dr)  # j broadcasts: piece data gathered once per column
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(jac > 0, jac / v, 0.0)
    out: FloatArray = np.sum(tw * f, axis=0)
    return out


def _moving_offset(tau: FloatArray, y0: FloatArray, g0: FloatArray,
                   c0: FloatArray) -> FloatArray:
    """``speedplan.core._law_kernel._moving_offset``, elementwise."""
    half = 0.5 * tau * np.sqrt(0.5 * np.abs(c0))
    safe = np.where(half == 0.0, 1.0, half)
    with np.errstate(over="ignore", invalid="ignore"):
        s_full = np.where(half == 0.0, 1.0, np.where(c0 > 0.0, np.sinh(2.0 * safe),
                                                     np.sin(2.0 * safe)) / (2.0 * safe))
        s_half = np.where(half == 0.0, 1.0, np.where(c0 > 0.0, np.sinh(safe),
                                                     np.sin(safe)) / safe)
    out: FloatArray = np.sqrt(y0) * tau * s_full + 0.25 * g0 * tau * tau * s_half * s_half
    return out


def invert(p: Any, T: FloatArray, j: IntArray, t: FloatArray,
           exact: np.ndarray) -> tuple[FloatArray, FloatArray]:
    """Offsets ``(dx, dr)`` reached at times ``t`` in pieces ``j`` (see ``TimeLaw._invert``).

    ``exact``: per piece, whether to take the closed form (``TimeLaw._exact_inverse``).
    """
    width = p.x[j + 1] - p.x[j]
    span_t = T[j + 1] - T[j]
    closed = exact[j]  # moving at both ends: neither standstill branch below applies
    rest_left = p.y[j] <= 0.0
    rest_right = (p.y_right[j] <= 0.0) & ~rest_left
    power = np.where(p.is_u[j], 3.0, 2.0)
    # Time measured from the offset's origin: the right knot for a right standstill.
    tau = np.where(rest_right, T[j + 1] - t, t - T[j])
    with np.errstate(divide="ignore", invalid="ignore"):
        frac = np.clip(np.where(span_t > 0, tau / span_t, 0.0), 0.0, 1.0)
    off = width * np.where(rest_left | rest_right, frac**power, frac)
    inner = (tau > 0) & (tau < span_t)  # at a knot the offset is exact
    lo, hi = np.zeros_like(off), width.copy()
    ttol = 1e-15 * np.maximum(span_t, 1e-300)
    act = np.flatnonzero(inner & ~closed)
    for _ in range(100):
        if act.size == 0:
            break
        ja, wa, oa, rr = j[act], width[act], off[act], rest_right[act]
        f = integrals(p, ja, 0.0 * oa, oa, rr) - tau[act]  # increasing in the offset
        lo[act] = np.where(f <= 0, oa, lo[act])
        hi[act] = np.where(f >= 0, oa, hi[act])
        v = _speed(p, ja, np.where(rr, wa - oa, oa), np.where(rr, oa, wa - oa))
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            newton = oa - f * v
        inside = (newton >= lo[act]) & (newton <= hi[act])
        converged = np.abs(f) <= ttol[act]
        new = np.where(converged, oa, np.where(inside, newton, 0.5 * (lo[act] + hi[act])))
        off[act] = new
        moving = ~converged & (np.abs(new - oa) > 4e-16 * np.maximum(np.abs(new), 1e-300))
        act = act[moving]
    off = np.where(tau >= span_t, width, np.where(tau <= 0, 0.0, off))
    dx = np.where(rest_right, width - off, off)
    dr = np.where(rest_right, off, width - off)
    # The closed form, from the knot nearer in time (that knot's offset kept exact).
    left = np.flatnonzero(inner & closed & (tau <= 0.5 * span_t))
    jl = j[left]
    dx[left] = np.clip(_moving_offset(tau[left], p.y[jl], p.g[jl], p.c[jl]), 0.0, width[left])
    dr[left] = width[left] - dx[left]
    right = np.flatnonzero(inner & closed & (tau > 0.5 * span_t))
    jr = j[right]
    dr[right] = np.clip(_moving_offset(T[jr + 1] - t[right], p.y_right[jr], -p.g_right[jr],
                                       p.c[jr]), 0.0, width[right])
    dx[right] = width[right] - dr[right]
    return dx, dr

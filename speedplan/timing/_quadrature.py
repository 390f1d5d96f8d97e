"""Compiled Gauss–Legendre quadrature of ``∫ ds / v`` for :class:`~speedplan.timing.TimeLaw`.

``TimeLaw.time_at`` runs this for every sample of a trajectory: ``verify()`` samples every
millisecond, i.e. 10^5 samples × 16 nodes for a two-minute path. Written with numpy arrays of
shape ``(samples, 16)`` it built a few dozen such temporaries per call and took most of
``plan()``'s wall time; as one loop it needs none. The arithmetic is that of the formulas in
:mod:`speedplan.timing.law` (``u`` from the nearer knot, the smoothstep end correction, the
``σ = y³`` substitution at standstill), so results agree with them to rounding.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..core.checks import FloatArray, IntArray
from ..geometry.pieces import GAUSS_NODES, GAUSS_WEIGHTS

__all__ = ["piece_integrals"]


@njit(cache=True, error_model="numpy", inline="always")
def _smoothstep(q: float, s0: float, length: float) -> float:
    z = (q - s0) / length
    return z * z * (3.0 - 2.0 * z)


@njit(cache=True, error_model="numpy")
def piece_integrals(
    j: IntArray, lo: FloatArray, hi: FloatArray, singular_at: FloatArray,
    x: FloatArray, gk: FloatArray, uc: FloatArray, c: float, s0: float, length: float,
    p: float,
) -> FloatArray:
    """``∫ ds / v`` over offsets ``[lo_i, hi_i]`` of piece ``j_i``, for every sample ``i``.

    ``x``, ``gk``, ``uc`` are the knots, slopes ``u'`` and values ``u`` of the interpolant,
    ``c`` the amplitude of the smoothstep correction over ``[s0, s0 + length]`` and ``p`` the
    exponent (``v = u^{1/(2p)}``). ``singular_at`` is -1 where the piece starts at standstill
    (then ``lo = 0``), +1 where it ends there (``hi`` is the piece width), 0 otherwise;
    offsets are then measured from the singular end and ``σ = y³`` removes the singularity.
    """
    out = np.empty(j.size)
    exponent = 0.5 / p
    for i in range(j.size):
        k = j[i]
        width = x[k + 1] - x[k]
        curv = (gk[k + 1] - gk[k]) / width
        span = hi[i] - lo[i]
        left, right = singular_at[i] < 0.0, singular_at[i] > 0.0
        acc = 0.0
        for g in range(GAUSS_NODES.size):  # the geometry's 16-point rule on [0, 1]
            y = GAUSS_NODES[g]
            if left:
                dx = span * y**3
                dr = width - dx
            elif right:
                dr = span * y**3
                dx = width - dr
            else:
                dx = lo[i] + span * y
                dr = width - dx
            jac = 3.0 * span * y**2 if (left or right) else span
            if jac == 0.0:
                continue
            # u from the nearer knot, accurate relative to its size next to a standstill.
            nearer_right = dx > dr
            if nearer_right:
                u = uc[k + 1] - gk[k + 1] * dr + 0.5 * curv * dr * dr
            else:
                u = uc[k] + gk[k] * dx + 0.5 * curv * dx * dx
            if c != 0.0:
                anchor = x[k + 1] if nearer_right else x[k]
                u = u + c * (_smoothstep(x[k] + dx, s0, length)
                             - _smoothstep(anchor, s0, length))
            acc += GAUSS_WEIGHTS[g] * (jac / max(u, 0.0) ** exponent)
        out[i] = acc
    return out

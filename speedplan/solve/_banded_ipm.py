"""Compiled iteration of the banded interior-point method (see :mod:`speedplan.solve.banded`).

Everything here runs under :func:`numba.njit`. One interior-point iteration at ``n = 1000``
is a few hundred small vector operations, which as separate numpy calls cost more than the
arithmetic itself; written as loops over nodes they compile to a few passes over memory.
Every array is allocated once per solve and updated in place: at ``n >= 10^4`` a fresh
multi-megabyte temporary per operation costs more in page faults than its arithmetic (a
third of the run time, measured). Compiled code is cached on disk (``cache=True``), so only
the first use after installation pays the compilation. Arithmetic follows numpy's error
model (division by zero gives ``inf``/``nan``, which the iteration detects and reports as a
numerical breakdown) rather than raising inside compiled code.

Notation follows CVXOPT's ``coneqp``: ``G x + s = b``, ``s ∈ K``, ``G' y + c = 0``, ``y ∈ K``
with ``x = (w, t, z)`` over the ``m`` interior nodes. ``K`` is a product of nonnegative
orthants (the linear rows) and ``2 m`` three-dimensional second-order cones, stored
column-wise in arrays of shape ``(3, 2 m)``: first the node cones ``z² <= w``, then the
cones ``t z >= 1``. Linear rows are ordered: acceleration (``m + 1``), braking (``m + 1``),
upper bounds (``m``), lower bounds (``kl``, nodes ``lk``), positive jerk rows (``k``, nodes
``jk``), negative jerk rows (``k``). Functions named ``*_into`` write their result into the
trailing array arguments.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from ..core.checks import FloatArray, IntArray

#: Fraction of the step to the cone boundary taken per iteration.
STEP = 0.99
#: Exponent of Mehrotra's centring heuristic ``σ = (1 - α_affine)^3``.
SIGMA_EXPONENT = 3.0
#: Relative gap below which each Newton solve is checked for iterative refinement.
REFINE_BELOW = 1e-3
#: The check refines when the solve's residual in ``G'Δy = bx``, relative like the dual
#: residual, exceeds this fraction of ``tol``: there it can matter for convergence (fine grids,
#: strongly varying ``J``); on most instances it is far smaller and a round would be wasted.
REFINE_RESIDUAL = 0.01
#: Iterations without halving the relative gap after which the method is declared stalled.
STALL_ITERATIONS = 5
#: Relative gap below which a stalled method reports STALLED; also the certified relative gap
#: with which :mod:`~speedplan.solve.banded` accepts any stop short of ``tol`` ("AlmostSolved").
ALMOST_GAP = 1e-6
#: Iterations without halving the relative gap after which the method gives up at any gap
#: (seen on a few long, strongly graded grids, where it jams near a gap of 1e-2; the caller
#: then falls back to Clarabel rather than spending ``max_iter`` iterations).
NO_PROGRESS_ITERATIONS = 20

#: Status codes returned by :func:`iterate`.
SOLVED, MAX_ITERATIONS, STALLED, NUMERICAL_ERROR, NO_PROGRESS = 0, 1, 2, 3, 4
STATUS_NAMES = ("Solved", "MaxIterations", "Stalled", "NumericalError", "NoProgress")


class Data(NamedTuple):
    """Problem data in internal units (see :func:`speedplan.solve.banded._prepare`)."""

    d0: FloatArray  # second-difference weights of w_{i-1}, w_i, w_{i+1}, shape (m,)
    d1: FloatArray
    d2: FloatArray
    jk: IntArray  # interior nodes with finite J
    cj: FloatArray  # coefficient of the second difference in their jerk rows
    lk: IntArray  # interior nodes with a positive lower bound
    ct: FloatArray  # objective coefficients of t
    cw: FloatArray  # coefficients of w in the acceleration rows
    b_lin: FloatArray  # right-hand side of the linear rows


class Scaling(NamedTuple):
    """Nesterov–Todd scaling ``W`` of the cones at the current ``(s, y)``.

    The linear rows' scaling ``W = diag(sqrt(s / y))`` is never formed: only ``W² = s / y``
    and ``λ² = s y`` enter the Newton system.
    """

    beta: FloatArray  # cones: W = β (2 v v' - J)
    v: FloatArray
    lam_s: FloatArray  # scaled point λ = W y = W⁻¹ s


class Factor(NamedTuple):
    """``L D L'`` factor of the reduced matrix, per-node elimination data and scratch."""

    l1: FloatArray  # L[i, i-1]
    l2: FloatArray  # L[i, i-2]
    dd: FloatArray  # D
    hl: FloatArray  # linear-row weights y / s
    a: FloatArray  # coupling of t_i to D̂_i w, zero where J = inf
    bwz: FloatArray  # coupling of z_i to w_i
    p: FloatArray  # inverse of the (t, z) block: [[p, q], [q, r]]
    q: FloatArray
    r: FloatArray
    mtt: FloatArray  # scratch of the assembly, shape (m,) each
    mzz: FloatArray
    mtz: FloatArray
    dg: FloatArray
    e: FloatArray
    off1: FloatArray
    off2: FloatArray


class Work(NamedTuple):
    """Scratch arrays of one Newton solve."""

    vl: FloatArray  # (n_lin,)
    gl: FloatArray
    vs: FloatArray  # (3, 2 m)
    rw: FloatArray  # (m,) each
    rt: FloatArray
    rz: FloatArray
    cw: FloatArray
    ct: FloatArray
    cz: FloatArray
    u: FloatArray


# --- per-cone and per-node scalar kernels (inlined) ----------------------------------------


@njit(cache=True, error_model="numpy", inline="always")
def _pad(w: FloatArray, i: int) -> float:
    """``w[i]`` with zero outside ``0 <= i < len(w)`` (the eliminated end values)."""
    if i < 0 or i >= w.size:
        return 0.0
    return float(w[i])


@njit(cache=True, error_model="numpy", inline="always")
def _second_diff(d: Data, w: FloatArray, i: int) -> float:
    return float(d.d0[i] * _pad(w, i - 1) + d.d1[i] * w[i] + d.d2[i] * _pad(w, i + 1))


@njit(cache=True, error_model="numpy")
def _jnorm2(u0: float, u1: float, u2: float) -> float:
    """``u' J u`` with ``J = diag(1, -1, -1)``, computed as ``(u_0 - |u_a|)(u_0 + |u_a|) - u_b²``.

    ``a`` is the larger of the two other components. Near the cone boundary the plain
    ``u_0² - u_1² - u_2²`` cancels to the square of the largest entry; pairing ``u_0`` with
    the largest entry first keeps the error relative to the smaller one.
    """
    a1, a2 = abs(u1), abs(u2)
    big, small = (a1, a2) if a1 >= a2 else (a2, a1)
    return (u0 - big) * (u0 + big) - small * small


@njit(cache=True, error_model="numpy", inline="always")
def _h_entries(sc: Scaling, c: int) -> tuple[float, float, float, float, float, float]:
    """Entries 00, 01, 02, 11, 12, 22 of cone ``c``'s ``H = W⁻² = (2 ŵ ŵ' - J) / β²``.

    ``ŵ = J wbar`` with the scaling point ``wbar = 2 v_0 v - e``.
    """
    v0, v1, v2 = sc.v[0, c], sc.v[1, c], sc.v[2, c]
    u0, u1, u2 = 2.0 * v0 * v0 - 1.0, -2.0 * v0 * v1, -2.0 * v0 * v2
    ib2 = 1.0 / (sc.beta[c] * sc.beta[c])
    return ((2.0 * u0 * u0 - 1.0) * ib2, 2.0 * u0 * u1 * ib2, 2.0 * u0 * u2 * ib2,
            (2.0 * u1 * u1 + 1.0) * ib2, 2.0 * u1 * u2 * ib2, (2.0 * u2 * u2 + 1.0) * ib2)


@njit(cache=True, error_model="numpy", inline="always")
def _apply_h(sc: Scaling, u0: float, u1: float, u2: float, c: int) -> tuple[float, float, float]:
    """``H u`` for cone ``c``."""
    h00, h01, h02, h11, h12, h22 = _h_entries(sc, c)
    return (h00 * u0 + h01 * u1 + h02 * u2, h01 * u0 + h11 * u1 + h12 * u2,
            h02 * u0 + h12 * u1 + h22 * u2)


@njit(cache=True, error_model="numpy", inline="always")
def _apply_w(sc: Scaling, u0: float, u1: float, u2: float, c: int) -> tuple[float, float, float]:
    """``W u`` for cone ``c``: ``W = β (2 v v' - J)``."""
    v0, v1, v2, bt = sc.v[0, c], sc.v[1, c], sc.v[2, c], sc.beta[c]
    vu = v0 * u0 + v1 * u1 + v2 * u2
    return bt * (2.0 * vu * v0 - u0), bt * (2.0 * vu * v1 + u1), bt * (2.0 * vu * v2 + u2)


@njit(cache=True, error_model="numpy", inline="always")
def _apply_winv(
    sc: Scaling, u0: float, u1: float, u2: float, c: int
) -> tuple[float, float, float]:
    """``W⁻¹ u`` for cone ``c``: ``W⁻¹ = (2 Jv (Jv)' - J) / β``."""
    j0, j1, j2, bt = sc.v[0, c], -sc.v[1, c], -sc.v[2, c], sc.beta[c]
    vu = j0 * u0 + j1 * u1 + j2 * u2
    return (2.0 * vu * j0 - u0) / bt, (2.0 * vu * j1 + u1) / bt, (2.0 * vu * j2 + u2) / bt


@njit(cache=True, error_model="numpy", inline="always")
def _jordan_solve(
    l0: float, l1: float, l2: float, b0: float, b1: float, b2: float
) -> tuple[float, float, float]:
    """Solve ``λ ∘ u = b`` for ``u`` (one cone)."""
    u0 = (l0 * b0 - l1 * b1 - l2 * b2) / _jnorm2(l0, l1, l2)
    return u0, (b1 - u0 * l1) / l0, (b2 - u0 * l2) / l0


# --- the constraint map G and its adjoint -------------------------------------------------


@njit(cache=True, error_model="numpy")
def g_lin_into(d: Data, w: FloatArray, t: FloatArray, out: FloatArray) -> None:
    """Linear rows of ``G x`` (no constants)."""
    m, k, kl = w.size, d.jk.size, d.lk.size
    nl = m + 1
    for j in range(nl):
        right = d.cw[j] * w[j] if j < m else 0.0
        left = d.cw[j - 1] * w[j - 1] if j > 0 else 0.0
        out[j] = right - left
        out[nl + j] = left - right
    for i in range(m):
        out[2 * nl + i] = w[i]
    base = 2 * nl + m
    for r in range(kl):
        out[base + r] = -w[d.lk[r]]
    base += kl
    for r in range(k):
        i = d.jk[r]
        jw = d.cj[r] * _second_diff(d, w, i)
        out[base + r] = jw - t[i]
        out[base + k + r] = -jw - t[i]


@njit(cache=True, error_model="numpy")
def g_soc_into(w: FloatArray, t: FloatArray, z: FloatArray, out: FloatArray) -> None:
    """Cone rows of ``G x`` (no constants), shape ``(3, 2 m)``."""
    m = w.size
    for i in range(m):
        out[0, i] = -w[i]
        out[1, i] = -2.0 * z[i]
        out[2, i] = -w[i]
        out[0, m + i] = -(t[i] + z[i])
        out[1, m + i] = -(t[i] - z[i])
        out[2, m + i] = 0.0


@njit(cache=True, error_model="numpy")
def _second_diff_t_into(d: Data, u: FloatArray, out: FloatArray) -> None:
    """``D̂' u`` for node values ``u``."""
    m = u.size
    for i in range(m):
        acc = d.d1[i] * u[i]
        if i + 1 < m:
            acc += d.d0[i + 1] * u[i + 1]
        if i > 0:
            acc += d.d2[i - 1] * u[i - 1]
        out[i] = acc


@njit(cache=True, error_model="numpy")
def g_adjoint_into(
    d: Data, yl: FloatArray, ys: FloatArray, gw: FloatArray, gt: FloatArray, gz: FloatArray,
    u: FloatArray,
) -> None:
    """``G' y`` split into its ``w``, ``t`` and ``z`` parts (``u`` is scratch)."""
    m, k, kl = d.cw.size, d.jk.size, d.lk.size
    nl = m + 1
    base_j = 2 * nl + m + kl
    for i in range(m):
        u[i] = 0.0
        gt[i] = -(ys[0, m + i] + ys[1, m + i])
        gz[i] = -2.0 * ys[1, i] - ys[0, m + i] + ys[1, m + i]
    for r in range(k):
        i = d.jk[r]
        jp, jm = yl[base_j + r], yl[base_j + k + r]
        u[i] = d.cj[r] * (jp - jm)
        gt[i] -= jp + jm
    _second_diff_t_into(d, u, gw)
    for i in range(m):
        acc_i = yl[i] - yl[nl + i]
        acc_n = yl[i + 1] - yl[nl + i + 1]
        gw[i] += (d.cw[i] * (acc_i - acc_n) + yl[2 * nl + i]
                  - ys[0, i] - ys[2, i])
    for r in range(kl):
        gw[d.lk[r]] -= yl[2 * nl + m + r]


# --- cones: steps, interiority, scaling --------------------------------------------------------


@njit(cache=True, error_model="numpy")
def max_step_soc(u: FloatArray, du: FloatArray) -> float:
    """Largest ``α`` with ``u + α du`` in every cone (``u`` interior); ``inf`` if unbounded."""
    best = np.inf
    for c in range(u.shape[1]):
        a = _jnorm2(du[0, c], du[1, c], du[2, c])
        b = u[0, c] * du[0, c] - u[1, c] * du[1, c] - u[2, c] * du[2, c]
        cc = _jnorm2(u[0, c], u[1, c], u[2, c])
        disc = b * b - a * cc
        root = np.inf
        if not (disc < 0.0 and a >= 0.0):
            # Roots of a α² + 2 b α + cc = 0 without cancellation: q / a and cc / q.
            sq = math.sqrt(max(disc, 0.0))
            q = -(b + math.copysign(sq, b))
            if a != 0.0:
                r1 = q / a
                if r1 > 0.0 and math.isfinite(r1):
                    root = min(root, r1)
            if q != 0.0:
                r2 = cc / q
                if r2 > 0.0 and math.isfinite(r2):
                    root = min(root, r2)
        # Also keep u_0 + α du_0 > 0 (the quadratic alone does not tell K from -K).
        if du[0, c] < 0.0:
            root = min(root, -u[0, c] / du[0, c])
        best = min(best, root)
    return best


@njit(cache=True, error_model="numpy")
def max_step_lin(u: FloatArray, du: FloatArray) -> float:
    """Largest ``α`` with ``u + α du >= 0`` (``u > 0``); ``inf`` if unbounded."""
    worst = 0.0
    for i in range(u.size):
        worst = max(worst, -du[i] / u[i])
    return 1.0 / worst if worst > 0.0 else np.inf


@njit(cache=True, error_model="numpy")
def _step_into_cones(u: FloatArray, alpha: float, du: FloatArray, out: FloatArray) -> bool:
    """``out = u + α du``; whether every cone of ``out`` is strictly interior."""
    inside = True
    for c in range(u.shape[1]):
        o0 = u[0, c] + alpha * du[0, c]
        o1 = u[1, c] + alpha * du[1, c]
        o2 = u[2, c] + alpha * du[2, c]
        out[0, c], out[1, c], out[2, c] = o0, o1, o2
        if not (o0 > 0.0 and _jnorm2(o0, o1, o2) > 0.0):
            inside = False
    return inside


@njit(cache=True, error_model="numpy")
def scaling_into(ss: FloatArray, ys: FloatArray, sc: Scaling) -> None:
    """Nesterov–Todd scaling of every cone (formulas of CVXOPT's ``misc.compute_scaling``)."""
    for c in range(ss.shape[1]):
        sn = math.sqrt(_jnorm2(ss[0, c], ss[1, c], ss[2, c]))
        yn = math.sqrt(_jnorm2(ys[0, c], ys[1, c], ys[2, c]))
        bt = math.sqrt(sn / yn)
        s0, s1, s2 = ss[0, c] / sn, ss[1, c] / sn, ss[2, c] / sn
        y0, y1, y2 = ys[0, c] / yn, ys[1, c] / yn, ys[2, c] / yn
        gamma = math.sqrt(0.5 * (1.0 + s0 * y0 + s1 * y1 + s2 * y2))
        wb0 = (s0 + y0) / (2.0 * gamma)
        wb1 = (s1 - y1) / (2.0 * gamma)
        wb2 = (s2 - y2) / (2.0 * gamma)
        nv = math.sqrt(2.0 * (wb0 + 1.0))
        sc.beta[c] = bt
        sc.v[0, c], sc.v[1, c], sc.v[2, c] = (wb0 + 1.0) / nv, wb1 / nv, wb2 / nv
        sc.lam_s[0, c], sc.lam_s[1, c], sc.lam_s[2, c] = _apply_w(
            sc, ys[0, c], ys[1, c], ys[2, c], c)


# --- the reduced (pentadiagonal) Newton system --------------------------------------------


@njit(cache=True, error_model="numpy")
def factor_into(d: Data, sc: Scaling, yl: FloatArray, sl: FloatArray, fac: Factor) -> bool:
    """Assemble the Schur complement in ``w`` of ``G' H G`` and factor it.

    The linear rows are weighted by ``yl / sl`` and the cones by ``H`` of ``sc``.
    Eliminating ``(t_i, z_i)`` node by node leaves a pentadiagonal matrix, factored as
    ``L D L'`` with a unit lower triangular ``L`` of bandwidth 2. Returns False if the
    matrix is not numerically positive definite.
    """
    m, k, kl = d.cw.size, d.jk.size, d.lk.size
    nl = m + 1
    hl = fac.hl
    for j in range(hl.size):
        hl[j] = yl[j] / sl[j]
    base_j = 2 * nl + m + kl
    mtt, mzz, mtz, dg, e, a = fac.mtt, fac.mzz, fac.mtz, fac.dg, fac.e, fac.a
    for i in range(m):
        h00, h01, h02, h11, h12, h22 = _h_entries(sc, i)
        g00, g01, _, g11, _, _ = _h_entries(sc, m + i)
        mtt[i] = g00 + 2.0 * g01 + g11
        mzz[i] = 4.0 * h11 + g00 - 2.0 * g01 + g11
        mtz[i] = g00 - g11
        fac.bwz[i] = 2.0 * (h01 + h12)
        dg[i] = hl[2 * nl + i] + (h00 + 2.0 * h02 + h22)
        a[i] = 0.0
        e[i] = 0.0
    for r in range(kl):
        j = 2 * nl + m + r
        dg[d.lk[r]] += hl[j]
    for r in range(k):
        i = d.jk[r]
        hp = hl[base_j + r]
        hm = hl[base_j + k + r]
        # Jerk weight after eliminating t: c²(H⁺ + H⁻) - p a², written without cancellation
        # as c² (4 H⁺H⁻ + κ (H⁺ + H⁻)) / (H⁺ + H⁻ + κ) with κ the cones' own weight of t.
        kappa = mtt[i] - mtz[i] * mtz[i] / mzz[i]
        hsum = hp + hm
        e[i] = d.cj[r] ** 2 * (4.0 * hp * hm + kappa * hsum) / (hsum + kappa)
        a[i] = -d.cj[r] * (hp - hm)
        mtt[i] += hsum
    for i in range(m):
        det = mtt[i] * mzz[i] - mtz[i] * mtz[i]
        fac.p[i], fac.q[i], fac.r[i] = mzz[i] / det, -mtz[i] / det, mtt[i] / det
    # Pentadiagonal S: diagonal (kept in dg), S[i-1, i] and S[i-2, i]; then L D L'.
    off1, off2, l1, l2, dd = fac.off1, fac.off2, fac.l1, fac.l2, fac.dd
    ok = True
    for i in range(m):
        gacc_i = hl[i] + hl[nl + i]
        gacc_n = hl[i + 1] + hl[nl + i + 1]
        f_i = -fac.q[i] * a[i] * fac.bwz[i]
        di = (e[i] * d.d1[i] ** 2 + 2.0 * f_i * d.d1[i] + dg[i] - fac.r[i] * fac.bwz[i] ** 2
              + d.cw[i] ** 2 * (gacc_i + gacc_n))
        if i + 1 < m:
            di += e[i + 1] * d.d0[i + 1] ** 2
        if i > 0:
            f_p = -fac.q[i - 1] * a[i - 1] * fac.bwz[i - 1]
            di += e[i - 1] * d.d2[i - 1] ** 2
            off1[i] = (d.d0[i] * (e[i] * d.d1[i] + f_i)
                       + d.d2[i - 1] * (e[i - 1] * d.d1[i - 1] + f_p)
                       - d.cw[i - 1] * d.cw[i] * gacc_i)
        if i > 1:
            off2[i] = e[i - 1] * d.d0[i - 1] * d.d2[i - 1]
            l2[i] = off2[i] / dd[i - 2]
            di -= l2[i] * l2[i] * dd[i - 2]
        else:
            l2[i] = 0.0
        if i > 0:
            b = off1[i]
            if i > 1:
                b -= l2[i] * l1[i - 1] * dd[i - 2]
            l1[i] = b / dd[i - 1]
            di -= l1[i] * l1[i] * dd[i - 1]
        else:
            l1[i] = 0.0
        if not (di > 0.0 and math.isfinite(di)):
            ok = False
            di = 1.0
        dd[i] = di
    return ok


@njit(cache=True, error_model="numpy")
def _solve_banded_inplace(fac: Factor, x: FloatArray) -> None:
    m = x.size
    for i in range(1, m):
        x[i] -= fac.l1[i] * x[i - 1]
        if i > 1:
            x[i] -= fac.l2[i] * x[i - 2]
    for i in range(m):
        x[i] /= fac.dd[i]
    for i in range(m - 2, -1, -1):
        x[i] -= fac.l1[i + 1] * x[i + 1]
        if i + 2 < m:
            x[i] -= fac.l2[i + 2] * x[i + 2]


@njit(cache=True, error_model="numpy")
def solve_normal_into(
    d: Data, fac: Factor, rw: FloatArray, rt: FloatArray, rz: FloatArray,
    dw: FloatArray, dt: FloatArray, dz: FloatArray, u: FloatArray,
) -> None:
    """Solve ``G' H G Δx = r`` by eliminating ``(t, z)`` node by node (``u`` is scratch)."""
    m = rw.size
    for i in range(m):
        dt[i] = fac.p[i] * rt[i] + fac.q[i] * rz[i]
        dz[i] = fac.q[i] * rt[i] + fac.r[i] * rz[i]
        u[i] = fac.a[i] * dt[i]
    _second_diff_t_into(d, u, dw)
    for i in range(m):
        dw[i] = rw[i] - dw[i] - fac.bwz[i] * dz[i]
    _solve_banded_inplace(fac, dw)
    for i in range(m):
        ct = fac.a[i] * _second_diff(d, dw, i)
        cz = fac.bwz[i] * dw[i]
        dt[i] -= fac.p[i] * ct + fac.q[i] * cz
        dz[i] -= fac.q[i] * ct + fac.r[i] * cz


@njit(cache=True, error_model="numpy")
def _dy_into(
    d: Data, sc: Scaling, fac: Factor, nw: Work, dw: FloatArray, dt: FloatArray,
    dz: FloatArray, byl: FloatArray, bys: FloatArray,
    dsl: FloatArray, dss: FloatArray, dyl: FloatArray, dys: FloatArray,
) -> None:
    """``Δs = by - G Δx`` and ``Δy = H G Δx - v``, linear and cone parts."""
    gl = nw.gl
    g_lin_into(d, dw, dt, gl)
    for j in range(gl.size):
        dyl[j] = fac.hl[j] * gl[j] - nw.vl[j]
        dsl[j] = byl[j] - gl[j]
    m = dw.size
    vs = nw.vs
    for c in range(2 * m):
        if c < m:
            g0, g1, g2 = -dw[c], -2.0 * dz[c], -dw[c]
        else:
            i = c - m
            g0, g1, g2 = -(dt[i] + dz[i]), -(dt[i] - dz[i]), 0.0
        dss[0, c] = bys[0, c] - g0
        dss[1, c] = bys[1, c] - g1
        dss[2, c] = bys[2, c] - g2
        h0, h1, h2 = _apply_h(sc, g0, g1, g2, c)
        dys[0, c] = h0 - vs[0, c]
        dys[1, c] = h1 - vs[1, c]
        dys[2, c] = h2 - vs[2, c]


@njit(cache=True, error_model="numpy")
def newton_into(
    d: Data, sc: Scaling, fac: Factor, nw: Work,
    sl: FloatArray, bw: FloatArray, bt: FloatArray, bz: FloatArray, byl: FloatArray,
    bys: FloatArray, bsl: FloatArray, bss: FloatArray, refine_above: float,
    dw: FloatArray, dt: FloatArray, dz: FloatArray,
    dsl: FloatArray, dss: FloatArray, dyl: FloatArray, dys: FloatArray,
) -> None:
    """Solve ``G'Δy = bx``, ``GΔx + Δs = by``, ``λ ∘ (WΔy + W⁻¹Δs) = bs``.

    ``sl`` is the linear slack (``λ W = s`` on the linear rows). One round of iterative
    refinement follows if the 2-norm of the residual ``bx - G'Δy`` exceeds ``refine_above``
    (``inf``: no refinement, and the residual is not computed).
    """
    # v = H by - W⁻¹ u with λ ∘ u = bs; then (G'HG) Δx = bx + G' v and Δy = H G Δx - v.
    for j in range(bsl.size):
        nw.vl[j] = fac.hl[j] * byl[j] - bsl[j] / sl[j]
    for c in range(bys.shape[1]):
        u0, u1, u2 = _jordan_solve(sc.lam_s[0, c], sc.lam_s[1, c], sc.lam_s[2, c],
                                   bss[0, c], bss[1, c], bss[2, c])
        w0, w1, w2 = _apply_winv(sc, u0, u1, u2, c)
        h0, h1, h2 = _apply_h(sc, bys[0, c], bys[1, c], bys[2, c], c)
        nw.vs[0, c], nw.vs[1, c], nw.vs[2, c] = h0 - w0, h1 - w1, h2 - w2
    rw, rt, rz = nw.rw, nw.rt, nw.rz
    g_adjoint_into(d, nw.vl, nw.vs, rw, rt, rz, nw.u)
    for i in range(rw.size):
        rw[i] += bw[i]
        rt[i] += bt[i]
        rz[i] += bz[i]
    solve_normal_into(d, fac, rw, rt, rz, dw, dt, dz, nw.u)
    _dy_into(d, sc, fac, nw, dw, dt, dz, byl, bys, dsl, dss, dyl, dys)
    # The last two equations hold by construction; only G'Δy = bx inherits the rounding of
    # the reduced solve, which grows as H becomes ill-conditioned near the optimum. A round
    # of iterative refinement with the same factor restores it.
    if refine_above < np.inf:
        g_adjoint_into(d, dyl, dys, rw, rt, rz, nw.u)
        res2 = 0.0
        for i in range(rw.size):
            rw[i] = bw[i] - rw[i]
            rt[i] = bt[i] - rt[i]
            rz[i] = bz[i] - rz[i]
            res2 += rw[i] * rw[i] + rt[i] * rt[i] + rz[i] * rz[i]
        if not math.sqrt(res2) > refine_above:
            return
        solve_normal_into(d, fac, rw, rt, rz, nw.cw, nw.ct, nw.cz, nw.u)
        for i in range(rw.size):
            dw[i] += nw.cw[i]
            dt[i] += nw.ct[i]
            dz[i] += nw.cz[i]
        _dy_into(d, sc, fac, nw, dw, dt, dz, byl, bys, dsl, dss, dyl, dys)


# --- driver ----------------------------------------------------------------------------------


@njit(cache=True, error_model="numpy")
def _dot(a: FloatArray, b: FloatArray) -> float:
    """``a · b`` over all entries, without a temporary."""
    fa, fb = a.reshape(a.size), b.reshape(b.size)
    acc = 0.0
    for i in range(fa.size):
        acc += fa[i] * fb[i]
    return acc


@njit(cache=True, error_model="numpy")
def _axpy(alpha: float, x: FloatArray, y: FloatArray) -> None:
    """``y += α x`` in place."""
    fx, fy = x.reshape(x.size), y.reshape(y.size)
    for i in range(fx.size):
        fy[i] += alpha * fx[i]


@njit(cache=True, error_model="numpy")
def _shift_into_cone(ul: FloatArray, us: FloatArray) -> None:
    """CVXOPT's initial-point rule: add ``(1 + t) e`` when ``u`` is not interior by margin."""
    worst = np.inf
    for i in range(ul.size):
        worst = min(worst, ul[i])
    for c in range(us.shape[1]):
        worst = min(worst, us[0, c] - math.hypot(us[1, c], us[2, c]))
    ts = -worst
    nrm = math.sqrt(_dot(ul, ul) + _dot(us, us))
    if ts >= -1e-8 * max(nrm, 1.0):
        ul += 1.0 + ts
        us[0] += 1.0 + ts


@njit(cache=True, error_model="numpy")
def iterate(
    d: Data, w0: FloatArray, t0: FloatArray, z0: FloatArray, tol: float, max_iter: int
) -> tuple[FloatArray, FloatArray, int, int]:
    """Mehrotra predictor–corrector iterations from the primal point ``(w0, t0, z0)``.

    The dual start is CVXOPT's default (least-norm ``y`` of ``G' y = -c``, shifted into the
    cones). Returns ``(w, yl, iterations, status)`` in internal units; ``status`` is one of the
    module's status codes.
    """
    m = d.cw.size
    nc = 2 * m
    n_lin = d.b_lin.size
    b_lin = d.b_lin
    b_soc = np.zeros((3, nc))  # constant part of the cone rows: (1, 0, -1) and (0, 0, 2)
    b_soc[0, :m] = 1.0
    b_soc[2, :m] = -1.0
    b_soc[2, m:] = 2.0
    nu = n_lin + nc  # barrier degree: one per linear row and per cone

    def lin() -> FloatArray:
        return np.zeros(n_lin)

    def node() -> FloatArray:
        return np.zeros(m)

    def cone() -> FloatArray:
        return np.zeros((3, nc))

    sc = Scaling(np.ones(nc), cone(), cone())
    sc.v[0] = 1.0  # W = I for the starting point
    fac = Factor(node(), node(), node(), lin(), node(), node(), node(), node(), node(), node(),
                 node(), node(), node(), node(), node(), node())
    nw = Work(lin(), lin(), cone(), node(), node(), node(), node(), node(), node(), node())
    w, t, z, gw, gt, gz = node(), node(), node(), node(), node(), node()
    sl, yl, ryl, bsl, dsl, dyl = lin(), lin(), lin(), lin(), lin(), lin()
    ss, ys, rys, bss, dss, dys = cone(), cone(), cone(), cone(), cone(), cone()
    ss_new, ys_new = cone(), cone()
    dw, dt, dz = node(), node(), node()

    factor_into(d, sc, np.ones(n_lin), np.ones(n_lin), fac)
    w[:] = w0
    t[:] = t0
    z[:] = z0
    g_lin_into(d, w, t, sl)
    g_soc_into(w, t, z, ss)
    sl[:] = b_lin - sl
    ss[:] = b_soc - ss
    solve_normal_into(d, fac, node(), -d.ct, node(), dw, dt, dz, nw.u)
    g_lin_into(d, dw, dt, yl)
    g_soc_into(dw, dt, dz, ys)
    _shift_into_cone(sl, ss)
    _shift_into_cone(yl, ys)
    res_x0 = max(1.0, math.sqrt(m))
    res_y0 = max(1.0, math.sqrt(_dot(b_lin, b_lin) + _dot(b_soc, b_soc)))
    status = MAX_ITERATIONS
    it = 0
    best_gap, stalled = np.inf, 0
    for it in range(max_iter + 1):
        # Residuals, stored negated: they are the right-hand sides -(G'y + c), -(Gx + s - b).
        g_adjoint_into(d, yl, ys, gw, gt, gz, nw.u)
        g_lin_into(d, w, t, ryl)
        g_soc_into(w, t, z, rys)
        for i in range(m):
            gw[i] = -gw[i]
            gt[i] = -(gt[i] + d.ct[i])
            gz[i] = -gz[i]
        for j in range(n_lin):
            ryl[j] = b_lin[j] - ryl[j] - sl[j]
        for c in range(nc):
            for r in range(3):
                rys[r, c] = -rys[r, c] - ss[r, c]
        ys_b = 0.0  # ys · b_soc with the constant part of the cone rows spelled out
        for i in range(m):
            rys[0, i] += 1.0
            rys[2, i] -= 1.0
            rys[2, m + i] += 2.0
            ys_b += ys[0, i] - ys[2, i] + 2.0 * ys[2, m + i]
        pcost = _dot(d.ct, t)
        dcost = -_dot(yl, b_lin) - ys_b
        gap = _dot(sl, yl) + _dot(ss, ys)
        pres = math.sqrt(_dot(ryl, ryl) + _dot(rys, rys)) / res_y0
        dres = math.sqrt(_dot(gw, gw) + _dot(gt, gt) + _dot(gz, gz)) / res_x0
        relgap = gap / max(min(abs(pcost), abs(dcost)), 1e-300)
        if pres <= tol and dres <= tol and relgap <= tol:
            status = SOLVED
            break
        # Near the optimum the NT scaling becomes ill-conditioned and rounding may stop
        # progress short of ``tol``; detect that instead of spinning to ``max_iter``. The gap
        # s'y may round to a tiny negative number once it has converged; clamped at 0, it
        # then counts as no further progress (unclamped, every negative value "halved" the
        # previous one and the method ran to max_iter, seen on a 20 000-node grid).
        if max(relgap, 0.0) < 0.5 * best_gap:
            best_gap, stalled = max(relgap, 0.0), 0
        else:
            stalled += 1
        if stalled >= STALL_ITERATIONS and best_gap < ALMOST_GAP:
            status = STALLED
            break
        if stalled >= NO_PROGRESS_ITERATIONS:
            status = NO_PROGRESS
            break
        if it == max_iter:
            break
        if not (math.isfinite(pres) and math.isfinite(dres) and math.isfinite(gap)):
            status = NUMERICAL_ERROR
            break
        scaling_into(ss, ys, sc)
        if not factor_into(d, sc, yl, sl, fac):
            status = NUMERICAL_ERROR
            break
        mu = gap / nu
        # Refinement only pays once the scaling is ill-conditioned, close to the optimum, and
        # only where the solve's own residual could show in the dual residual's test.
        refine_above = REFINE_RESIDUAL * tol * res_x0 if relgap < REFINE_BELOW else np.inf
        # Right-hand side -λ∘λ (λ∘λ = s y on the linear rows).
        for j in range(n_lin):
            bsl[j] = -sl[j] * yl[j]
        lam = sc.lam_s
        for c in range(nc):
            bss[0, c] = -(lam[0, c] ** 2 + lam[1, c] ** 2 + lam[2, c] ** 2)
            bss[1, c] = -2.0 * lam[0, c] * lam[1, c]
            bss[2, c] = -2.0 * lam[0, c] * lam[2, c]
        # Predictor (affine-scaling) direction.
        newton_into(d, sc, fac, nw, sl, gw, gt, gz, ryl, rys, bsl, bss, refine_above,
                    dw, dt, dz, dsl, dss, dyl, dys)
        alpha = min(max_step_lin(sl, dsl), max_step_lin(yl, dyl),
                    max_step_soc(ss, dss), max_step_soc(ys, dys))
        sigma = (1.0 - min(1.0, alpha)) ** SIGMA_EXPONENT
        # Corrector: second-order term and centring, same factorisation.
        for j in range(n_lin):
            bsl[j] = -sl[j] * yl[j] - dsl[j] * dyl[j] + sigma * mu
        for c in range(nc):
            a0, a1, a2 = _apply_winv(sc, dss[0, c], dss[1, c], dss[2, c], c)
            b0, b1, b2 = _apply_w(sc, dys[0, c], dys[1, c], dys[2, c], c)
            bss[0, c] += -(a0 * b0 + a1 * b1 + a2 * b2) + sigma * mu
            bss[1, c] += -(a0 * b1 + b0 * a1)
            bss[2, c] += -(a0 * b2 + b0 * a2)
        newton_into(d, sc, fac, nw, sl, gw, gt, gz, ryl, rys, bsl, bss, refine_above,
                    dw, dt, dz, dsl, dss, dyl, dys)
        alpha_p = min(1.0, STEP * min(
            max_step_lin(sl, dsl), max_step_lin(yl, dyl),
            max_step_soc(ss, dss), max_step_soc(ys, dys)))
        if not (math.isfinite(alpha_p) and alpha_p > 0.0):
            status = NUMERICAL_ERROR
            break
        # The closed-form step to the boundary can be off by rounding for nearly degenerate
        # cones; halve the step until every cone is strictly interior.
        inside = False
        for _ in range(30):
            inside_s = _step_into_cones(ss, alpha_p, dss, ss_new)
            if inside_s and _step_into_cones(ys, alpha_p, dys, ys_new):
                inside = True
                break
            alpha_p *= 0.5
        if not inside:
            status = NUMERICAL_ERROR
            break
        _axpy(alpha_p, dw, w)
        _axpy(alpha_p, dt, t)
        _axpy(alpha_p, dz, z)
        _axpy(alpha_p, dsl, sl)
        _axpy(alpha_p, dyl, yl)
        ss, ss_new = ss_new, ss
        ys, ys_new = ys_new, ys
    return w, yl, it, status

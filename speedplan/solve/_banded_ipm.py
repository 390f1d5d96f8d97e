"""Compiled iteration of the banded interior-point method (see :mod:`speedplan.solve.banded`).

Everything here runs under :func:`numba.njit`: one interior-point iteration at ``n = 1000``
is a few hundred small vector operations, which as separate numpy calls cost more than the
arithmetic itself. Written as loops over nodes they compile to one pass each; an iteration
then costs O(n) arithmetic and nothing per call. Compiled code is cached on disk
(``cache=True``), so only the first use after installation pays the compilation.

Notation follows CVXOPT's ``coneqp``: ``G x + s = b``, ``s ∈ K``, ``G' y + c = 0``, ``y ∈ K``
with ``x = (w, t, z)`` over the ``m`` interior nodes. ``K`` is a product of nonnegative
orthants (the linear rows) and ``2 m`` three-dimensional second-order cones, stored
column-wise in arrays of shape ``(3, 2 m)``: first the node cones ``z² <= w``, then the
cones ``t z >= 1``. Linear rows are ordered: acceleration (``m + 1``), braking (``m + 1``),
upper bounds (``m``), lower bounds (``kl``, nodes ``lk``), positive jerk rows (``k``, nodes
``jk``), negative jerk rows (``k``).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from .._checks import FloatArray, IntArray

#: Fraction of the step to the cone boundary taken per iteration.
STEP = 0.99
#: Exponent of Mehrotra's centring heuristic ``σ = (1 - α_affine)^3``.
SIGMA_EXPONENT = 3.0
#: Relative gap below which each Newton solve gets one round of iterative refinement.
REFINE_BELOW = 1e-3
#: Iterations without halving the relative gap after which the method is declared stalled.
STALL_ITERATIONS = 5
#: Certified relative gap accepted (as status "AlmostSolved") when the method stalls.
ALMOST_GAP = 1e-6

#: Status codes returned by :func:`iterate`.
SOLVED, MAX_ITERATIONS, STALLED, NUMERICAL_ERROR = 0, 1, 2, 3
STATUS_NAMES = ("Solved", "MaxIterations", "Stalled", "NumericalError")


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
    row: FloatArray  # scale of each linear row
    b_lin: FloatArray  # right-hand side of the linear rows


# --- the constraint map G and its adjoint -------------------------------------------------


@njit(cache=True, inline="always")
def _pad(w: FloatArray, i: int) -> float:
    """``w[i]`` with zero outside ``0 <= i < len(w)`` (the eliminated end values)."""
    if i < 0 or i >= w.size:
        return 0.0
    return float(w[i])


@njit(cache=True, inline="always")
def _second_diff(d: Data, w: FloatArray, i: int) -> float:
    return float(d.d0[i] * _pad(w, i - 1) + d.d1[i] * w[i] + d.d2[i] * _pad(w, i + 1))


@njit(cache=True)
def g_lin(d: Data, w: FloatArray, t: FloatArray) -> FloatArray:
    """Linear rows of ``G x`` (no constants)."""
    m, k, kl = w.size, d.jk.size, d.lk.size
    nl = m + 1
    out = np.empty(d.row.size)
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
    return out * d.row


@njit(cache=True)
def g_soc(w: FloatArray, t: FloatArray, z: FloatArray) -> FloatArray:
    """Cone rows of ``G x`` (no constants), shape ``(3, 2 m)``."""
    m = w.size
    out = np.zeros((3, 2 * m))
    for i in range(m):
        out[0, i] = -w[i]
        out[1, i] = -2.0 * z[i]
        out[2, i] = -w[i]
        out[0, m + i] = -(t[i] + z[i])
        out[1, m + i] = -(t[i] - z[i])
    return out


@njit(cache=True)
def _second_diff_t(d: Data, u: FloatArray) -> FloatArray:
    """``D̂' u`` for node values ``u``."""
    m = u.size
    out = np.empty(m)
    for i in range(m):
        acc = d.d1[i] * u[i]
        if i + 1 < m:
            acc += d.d0[i + 1] * u[i + 1]
        if i > 0:
            acc += d.d2[i - 1] * u[i - 1]
        out[i] = acc
    return out


@njit(cache=True)
def g_adjoint(
    d: Data, yl: FloatArray, ys: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``G' y`` split into its ``w``, ``t`` and ``z`` parts."""
    m, k, kl = d.cw.size, d.jk.size, d.lk.size
    nl = m + 1
    y = yl * d.row
    base_j = 2 * nl + m + kl
    u = np.zeros(m)
    gt = np.empty(m)
    gz = np.empty(m)
    for i in range(m):
        gt[i] = -(ys[0, m + i] + ys[1, m + i])
        gz[i] = -2.0 * ys[1, i] - ys[0, m + i] + ys[1, m + i]
    for r in range(k):
        i = d.jk[r]
        jp, jm = y[base_j + r], y[base_j + k + r]
        u[i] = d.cj[r] * (jp - jm)
        gt[i] -= jp + jm
    gw = _second_diff_t(d, u)
    for i in range(m):
        acc_i = y[i] - y[nl + i]
        acc_n = y[i + 1] - y[nl + i + 1]
        gw[i] += d.cw[i] * (acc_i - acc_n) + y[2 * nl + i] - ys[0, i] - ys[2, i]
    for r in range(kl):
        gw[d.lk[r]] -= y[2 * nl + m + r]
    return gw, gt, gz


# --- second-order cone algebra ---------------------------------------------------------------


@njit(cache=True)
def _jnorm2(u0: float, u1: float, u2: float) -> float:
    """``u' J u`` with ``J = diag(1, -1, -1)``, computed as ``(u_0 - |u_a|)(u_0 + |u_a|) - u_b²``.

    ``a`` is the larger of the two other components. Near the cone boundary the plain
    ``u_0² - u_1² - u_2²`` cancels to the square of the largest entry; pairing ``u_0`` with
    the largest entry first keeps the error relative to the smaller one.
    """
    a1, a2 = abs(u1), abs(u2)
    big, small = (a1, a2) if a1 >= a2 else (a2, a1)
    return (u0 - big) * (u0 + big) - small * small


@njit(cache=True)
def jordan(u: FloatArray, v: FloatArray) -> FloatArray:
    """Jordan product ``u ∘ v = (u'v, u_0 v̄ + v_0 ū)`` per cone."""
    out = np.empty_like(u)
    for c in range(u.shape[1]):
        out[0, c] = u[0, c] * v[0, c] + u[1, c] * v[1, c] + u[2, c] * v[2, c]
        out[1, c] = u[0, c] * v[1, c] + v[0, c] * u[1, c]
        out[2, c] = u[0, c] * v[2, c] + v[0, c] * u[2, c]
    return out


@njit(cache=True)
def _jordan_solve(lam: FloatArray, b: FloatArray) -> FloatArray:
    """Solve ``lam ∘ u = b`` for ``u`` per cone."""
    out = np.empty_like(b)
    for c in range(b.shape[1]):
        u0 = (lam[0, c] * b[0, c] - lam[1, c] * b[1, c] - lam[2, c] * b[2, c]) / _jnorm2(
            lam[0, c], lam[1, c], lam[2, c])
        out[0, c] = u0
        out[1, c] = (b[1, c] - u0 * lam[1, c]) / lam[0, c]
        out[2, c] = (b[2, c] - u0 * lam[2, c]) / lam[0, c]
    return out


@njit(cache=True)
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


@njit(cache=True)
def max_step_lin(u: FloatArray, du: FloatArray) -> float:
    """Largest ``α`` with ``u + α du >= 0`` (``u > 0``); ``inf`` if unbounded."""
    worst = 0.0
    for i in range(u.size):
        worst = max(worst, -du[i] / u[i])
    return 1.0 / worst if worst > 0.0 else np.inf


@njit(cache=True)
def interior_soc(u: FloatArray) -> bool:
    """Whether every cone of ``u`` is strictly interior."""
    for c in range(u.shape[1]):
        if not (u[0, c] > 0.0 and _jnorm2(u[0, c], u[1, c], u[2, c]) > 0.0):
            return False
    return True


class Scaling(NamedTuple):
    """Nesterov–Todd scaling ``W`` at the current ``(s, y)``."""

    wl: FloatArray  # linear: W = diag(sqrt(s / y))
    beta: FloatArray  # cones: W = β (2 v v' - J)
    v: FloatArray
    lam_l: FloatArray  # scaled point λ = W y = W⁻¹ s
    lam_s: FloatArray


@njit(cache=True)
def scaling(sl: FloatArray, yl: FloatArray, ss: FloatArray, ys: FloatArray) -> Scaling:
    """Nesterov–Todd scaling of every cone (formulas of CVXOPT's ``misc.compute_scaling``)."""
    wl = np.sqrt(sl / yl)
    lam_l = np.sqrt(sl * yl)
    nc = ss.shape[1]
    beta = np.empty(nc)
    v = np.empty((3, nc))
    lam_s = np.empty((3, nc))
    for c in range(nc):
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
        v0, v1, v2 = (wb0 + 1.0) / nv, wb1 / nv, wb2 / nv
        beta[c] = bt
        v[0, c], v[1, c], v[2, c] = v0, v1, v2
        # λ = W y.
        vu = v0 * ys[0, c] + v1 * ys[1, c] + v2 * ys[2, c]
        lam_s[0, c] = bt * (2.0 * vu * v0 - ys[0, c])
        lam_s[1, c] = bt * (2.0 * vu * v1 + ys[1, c])
        lam_s[2, c] = bt * (2.0 * vu * v2 + ys[2, c])
    return Scaling(wl, beta, v, lam_l, lam_s)


@njit(cache=True)
def identity_scaling(n_lin: int, n_cones: int) -> Scaling:
    """``W = I`` (``v = e``, ``β = 1``), used for the starting point."""
    v = np.zeros((3, n_cones))
    v[0] = 1.0
    ones = np.ones(n_lin)
    return Scaling(ones, np.ones(n_cones), v, ones, v)


@njit(cache=True, inline="always")
def _h_entries(sc: Scaling, c: int) -> tuple[float, float, float, float, float, float]:
    """Entries 00, 01, 02, 11, 12, 22 of cone ``c``'s ``H = W⁻² = (2 ŵ ŵ' - J) / β²``.

    ``ŵ = J wbar`` with the scaling point ``wbar = 2 v_0 v - e``.
    """
    v0, v1, v2 = sc.v[0, c], sc.v[1, c], sc.v[2, c]
    u0, u1, u2 = 2.0 * v0 * v0 - 1.0, -2.0 * v0 * v1, -2.0 * v0 * v2
    ib2 = 1.0 / (sc.beta[c] * sc.beta[c])
    return ((2.0 * u0 * u0 - 1.0) * ib2, 2.0 * u0 * u1 * ib2, 2.0 * u0 * u2 * ib2,
            (2.0 * u1 * u1 + 1.0) * ib2, 2.0 * u1 * u2 * ib2, (2.0 * u2 * u2 + 1.0) * ib2)


@njit(cache=True)
def apply_w(sc: Scaling, u: FloatArray) -> FloatArray:
    """``W u`` on the cone part."""
    out = np.empty_like(u)
    v, beta = sc.v, sc.beta
    for c in range(u.shape[1]):
        vu = v[0, c] * u[0, c] + v[1, c] * u[1, c] + v[2, c] * u[2, c]
        out[0, c] = beta[c] * (2.0 * vu * v[0, c] - u[0, c])
        out[1, c] = beta[c] * (2.0 * vu * v[1, c] + u[1, c])
        out[2, c] = beta[c] * (2.0 * vu * v[2, c] + u[2, c])
    return out


@njit(cache=True)
def apply_winv(sc: Scaling, u: FloatArray) -> FloatArray:
    """``W⁻¹ u`` on the cone part: ``W⁻¹ = (2 Jv (Jv)' - J) / β``."""
    out = np.empty_like(u)
    v, beta = sc.v, sc.beta
    for c in range(u.shape[1]):
        j0, j1, j2 = v[0, c], -v[1, c], -v[2, c]
        vu = j0 * u[0, c] + j1 * u[1, c] + j2 * u[2, c]
        out[0, c] = (2.0 * vu * j0 - u[0, c]) / beta[c]
        out[1, c] = (2.0 * vu * j1 + u[1, c]) / beta[c]
        out[2, c] = (2.0 * vu * j2 + u[2, c]) / beta[c]
    return out


@njit(cache=True, inline="always")
def _apply_h(sc: Scaling, u0: float, u1: float, u2: float, c: int) -> tuple[float, float, float]:
    """``H u`` for cone ``c``."""
    h00, h01, h02, h11, h12, h22 = _h_entries(sc, c)
    return (h00 * u0 + h01 * u1 + h02 * u2, h01 * u0 + h11 * u1 + h12 * u2,
            h02 * u0 + h12 * u1 + h22 * u2)


# --- the reduced (pentadiagonal) Newton system --------------------------------------------


class Factor(NamedTuple):
    """``L D L'`` factor of the reduced matrix and the per-node 2×2 elimination data."""

    l1: FloatArray  # L[i, i-1]
    l2: FloatArray  # L[i, i-2]
    dd: FloatArray  # D
    hl: FloatArray  # linear-row weights y / s
    a: FloatArray  # coupling of t_i to D̂_i w, zero where J = inf
    bwz: FloatArray  # coupling of z_i to w_i
    p: FloatArray  # inverse of the (t, z) block: [[p, q], [q, r]]
    q: FloatArray
    r: FloatArray
    ok: bool  # False if the matrix was not numerically positive definite


@njit(cache=True)
def factor(d: Data, sc: Scaling, hl_rows: FloatArray) -> Factor:
    """Assemble the Schur complement in ``w`` of ``G' H G`` and factor it.

    ``hl_rows`` are the weights of the linear rows and ``sc`` gives the cones' 3×3 blocks
    of ``H``. Eliminating ``(t_i, z_i)`` node by node leaves a pentadiagonal
    matrix, factored as ``L D L'`` with a unit lower triangular ``L`` of bandwidth 2.
    """
    m, k, kl = d.cw.size, d.jk.size, d.lk.size
    nl = m + 1
    hl = hl_rows * d.row * d.row  # weights of the unscaled rows
    base_j = 2 * nl + m + kl
    mtt = np.empty(m)
    mzz = np.empty(m)
    mtz = np.empty(m)
    bwz = np.empty(m)
    dg = np.empty(m)
    for i in range(m):
        h00, h01, h02, h11, h12, h22 = _h_entries(sc, i)
        g00, g01, _, g11, _, _ = _h_entries(sc, m + i)
        mtt[i] = g00 + 2.0 * g01 + g11
        mzz[i] = 4.0 * h11 + g00 - 2.0 * g01 + g11
        mtz[i] = g00 - g11
        bwz[i] = 2.0 * (h01 + h12)
        dg[i] = hl[2 * nl + i] + (h00 + 2.0 * h02 + h22)
    for r in range(kl):
        dg[d.lk[r]] += hl[2 * nl + m + r]
    a = np.zeros(m)
    e = np.zeros(m)
    for r in range(k):
        i = d.jk[r]
        hp, hm = hl[base_j + r], hl[base_j + k + r]
        # Jerk weight after eliminating t: c²(H⁺ + H⁻) - p a², written without cancellation
        # as c² (4 H⁺H⁻ + κ (H⁺ + H⁻)) / (H⁺ + H⁻ + κ) with κ the cones' own weight of t.
        kappa = mtt[i] - mtz[i] * mtz[i] / mzz[i]
        hsum = hp + hm
        e[i] = d.cj[r] ** 2 * (4.0 * hp * hm + kappa * hsum) / (hsum + kappa)
        a[i] = -d.cj[r] * (hp - hm)
        mtt[i] += hsum
    det = mtt * mzz - mtz * mtz
    p, q, rr = mzz / det, -mtz / det, mtt / det
    f = -q * a * bwz
    # Pentadiagonal S: diagonal, S[i-1, i] and S[i-2, i].
    diag = np.empty(m)
    off1 = np.zeros(m)
    off2 = np.zeros(m)
    for i in range(m):
        gacc_i = hl[i] + hl[nl + i]
        gacc_n = hl[i + 1] + hl[nl + i + 1]
        ef = e[i] * d.d1[i] + f[i]
        val = e[i] * d.d1[i] ** 2 + 2.0 * f[i] * d.d1[i] + dg[i] - rr[i] * bwz[i] ** 2
        val += d.cw[i] ** 2 * (gacc_i + gacc_n)
        if i + 1 < m:
            val += e[i + 1] * d.d0[i + 1] ** 2
        if i > 0:
            val += e[i - 1] * d.d2[i - 1] ** 2
            off1[i] = (d.d0[i] * ef + d.d2[i - 1] * (e[i - 1] * d.d1[i - 1] + f[i - 1])
                       - d.cw[i - 1] * d.cw[i] * gacc_i)
        if i > 1:
            off2[i] = e[i - 1] * d.d0[i - 1] * d.d2[i - 1]
        diag[i] = val
    l1 = np.zeros(m)
    l2 = np.zeros(m)
    dd = np.empty(m)
    ok = True
    for i in range(m):
        di = diag[i]
        if i > 1:
            l2[i] = off2[i] / dd[i - 2]
            di -= l2[i] * l2[i] * dd[i - 2]
        if i > 0:
            b = off1[i]
            if i > 1:
                b -= l2[i] * l1[i - 1] * dd[i - 2]
            l1[i] = b / dd[i - 1]
            di -= l1[i] * l1[i] * dd[i - 1]
        if not (di > 0.0 and math.isfinite(di)):
            ok = False
            di = 1.0
        dd[i] = di
    return Factor(l1, l2, dd, hl_rows, a, bwz, p, q, rr, ok)


@njit(cache=True)
def _solve_banded(fac: Factor, rhs: FloatArray) -> FloatArray:
    x = rhs.copy()
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
    return x


@njit(cache=True)
def solve_normal(
    d: Data, fac: Factor, rw: FloatArray, rt: FloatArray, rz: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Solve ``G' H G Δx = r`` by eliminating ``(t, z)`` node by node."""
    m = rw.size
    rho_t = np.empty(m)
    rho_z = np.empty(m)
    u = np.empty(m)
    for i in range(m):
        rho_t[i] = fac.p[i] * rt[i] + fac.q[i] * rz[i]
        rho_z[i] = fac.q[i] * rt[i] + fac.r[i] * rz[i]
        u[i] = fac.a[i] * rho_t[i]
    rhs = _second_diff_t(d, u)
    for i in range(m):
        rhs[i] = rw[i] - rhs[i] - fac.bwz[i] * rho_z[i]
    dw = _solve_banded(fac, rhs)
    for i in range(m):
        ct = fac.a[i] * _second_diff(d, dw, i)
        cz = fac.bwz[i] * dw[i]
        rho_t[i] -= fac.p[i] * ct + fac.q[i] * cz
        rho_z[i] -= fac.q[i] * ct + fac.r[i] * cz
    return dw, rho_t, rho_z


@njit(cache=True)
def _dy(
    d: Data, sc: Scaling, fac: Factor, dw: FloatArray, dt: FloatArray, dz: FloatArray,
    vl: FloatArray, vs: FloatArray, byl: FloatArray, bys: FloatArray,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """``Δs = by - G Δx`` and ``Δy = H G Δx - v``, linear and cone parts."""
    gl = g_lin(d, dw, dt)
    dyl = fac.hl * gl - vl
    dsl = byl - gl
    m = dw.size
    dss = np.empty((3, 2 * m))
    dys = np.empty((3, 2 * m))
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
    return dsl, dss, dyl, dys


@njit(cache=True)
def newton(
    d: Data,
    sc: Scaling,
    fac: Factor,
    bw: FloatArray,
    bt: FloatArray,
    bz: FloatArray,
    byl: FloatArray,
    bys: FloatArray,
    bsl: FloatArray,
    bss: FloatArray,
    refine: int,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """Solve ``G'Δy = bx``, ``GΔx + Δs = by``, ``λ ∘ (WΔy + W⁻¹Δs) = bs``.

    Returns ``Δw, Δt, Δz, Δs (lin, cone), Δy (lin, cone)``.
    """
    # v = H by - W⁻¹ u with λ ∘ u = bs; then (G'HG) Δx = bx + G' v and Δy = H G Δx - v.
    vl = fac.hl * byl - bsl / (sc.lam_l * sc.wl)
    us = apply_winv(sc, _jordan_solve(sc.lam_s, bss))
    vs = np.empty_like(bys)
    for c in range(bys.shape[1]):
        h0, h1, h2 = _apply_h(sc, bys[0, c], bys[1, c], bys[2, c], c)
        vs[0, c] = h0 - us[0, c]
        vs[1, c] = h1 - us[1, c]
        vs[2, c] = h2 - us[2, c]
    gw, gt, gz = g_adjoint(d, vl, vs)
    dw, dt, dz = solve_normal(d, fac, bw + gw, bt + gt, bz + gz)
    dsl, dss, dyl, dys = _dy(d, sc, fac, dw, dt, dz, vl, vs, byl, bys)
    # The last two equations hold by construction; only G'Δy = bx inherits the rounding of
    # the reduced solve, which grows as H becomes ill-conditioned near the optimum. A round
    # of iterative refinement with the same factor restores it.
    for _ in range(refine):
        ew, et, ez = g_adjoint(d, dyl, dys)
        cw, ct, cz = solve_normal(d, fac, bw - ew, bt - et, bz - ez)
        dw, dt, dz = dw + cw, dt + ct, dz + cz
        dsl, dss, dyl, dys = _dy(d, sc, fac, dw, dt, dz, vl, vs, byl, bys)
    return dw, dt, dz, dsl, dss, dyl, dys


# --- driver ----------------------------------------------------------------------------------


@njit(cache=True)
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


@njit(cache=True)
def _dot(a: FloatArray, b: FloatArray) -> float:
    """``a · b`` over all entries, without a temporary."""
    fa, fb = a.reshape(a.size), b.reshape(b.size)
    acc = 0.0
    for i in range(fa.size):
        acc += fa[i] * fb[i]
    return acc


@njit(cache=True)
def _b_soc(m: int) -> FloatArray:
    """Constant part of the cone rows: ``(1, 0, -1)`` and ``(0, 0, 2)``."""
    b = np.zeros((3, 2 * m))
    for i in range(m):
        b[0, i] = 1.0
        b[2, i] = -1.0
        b[2, m + i] = 2.0
    return b


@njit(cache=True)
def iterate(d: Data, tol: float, max_iter: int) -> tuple[FloatArray, FloatArray, int, int]:
    """Mehrotra predictor–corrector iterations from CVXOPT's default starting point.

    Returns ``(w, yl, iterations, status)`` in internal units; ``status`` is one of the
    module's status codes.
    """
    m = d.cw.size
    n_lin = d.row.size
    b_lin, b_soc = d.b_lin, _b_soc(m)
    nu = n_lin + 2 * m  # barrier degree: one per linear row and per cone
    fac = factor(d, identity_scaling(n_lin, 2 * m), np.ones(n_lin))
    # CVXOPT's default start: least-squares x of G x = b, least-norm y of G' y = -c, both
    # shifted into the cones.
    gw0, gt0, gz0 = g_adjoint(d, b_lin, b_soc)
    w, t, z = solve_normal(d, fac, gw0, gt0, gz0)
    sl = b_lin - g_lin(d, w, t)
    ss = b_soc - g_soc(w, t, z)
    uw, ut, uz = solve_normal(d, fac, np.zeros(m), -d.ct, np.zeros(m))
    yl = g_lin(d, uw, ut)
    ys = g_soc(uw, ut, uz)
    _shift_into_cone(sl, ss)
    _shift_into_cone(yl, ys)
    res_x0 = max(1.0, math.sqrt(m))
    res_y0 = max(1.0, math.sqrt(_dot(b_lin, b_lin) + _dot(b_soc, b_soc)))
    status = MAX_ITERATIONS
    it = 0
    best_gap, stalled = np.inf, 0
    for it in range(max_iter + 1):
        gw, gt, gz = g_adjoint(d, yl, ys)
        gt += d.ct
        ryl = g_lin(d, w, t) + sl - b_lin
        rys = g_soc(w, t, z) + ss - b_soc
        pcost = _dot(d.ct, t)
        dcost = -_dot(yl, b_lin) - _dot(ys, b_soc)
        gap = _dot(sl, yl) + _dot(ss, ys)
        pres = math.sqrt(_dot(ryl, ryl) + _dot(rys, rys)) / res_y0
        dres = math.sqrt(_dot(gw, gw) + _dot(gt, gt) + _dot(gz, gz)) / res_x0
        relgap = gap / max(min(abs(pcost), abs(dcost)), 1e-300)
        if pres <= tol and dres <= tol and relgap <= tol:
            status = SOLVED
            break
        # Near the optimum the NT scaling becomes ill-conditioned and rounding may stop
        # progress short of ``tol``; detect that instead of spinning to ``max_iter``.
        if relgap < 0.5 * best_gap:
            best_gap, stalled = relgap, 0
        else:
            stalled += 1
        if stalled >= STALL_ITERATIONS and best_gap < ALMOST_GAP:
            status = STALLED
            break
        if it == max_iter:
            break
        if not (math.isfinite(pres) and math.isfinite(dres) and math.isfinite(gap)):
            status = NUMERICAL_ERROR
            break
        sc = scaling(sl, yl, ss, ys)
        fac = factor(d, sc, yl / sl)
        if not fac.ok:
            status = NUMERICAL_ERROR
            break
        mu = gap / nu
        # Refinement only pays once the scaling is ill-conditioned, close to the optimum.
        refine = 1 if relgap < REFINE_BELOW else 0
        lam_sq_l = sc.lam_l * sc.lam_l
        lam_sq_s = jordan(sc.lam_s, sc.lam_s)
        # Predictor (affine-scaling) direction.
        dw, dt, dz, dsl, dss, dyl, dys = newton(
            d, sc, fac, -gw, -gt, -gz, -ryl, -rys, -lam_sq_l, -lam_sq_s, refine)
        alpha = min(max_step_lin(sl, dsl), max_step_lin(yl, dyl),
                    max_step_soc(ss, dss), max_step_soc(ys, dys))
        sigma = (1.0 - min(1.0, alpha)) ** SIGMA_EXPONENT
        # Corrector: second-order term and centring, same factorisation.
        cor_s = jordan(apply_winv(sc, dss), apply_w(sc, dys))
        cen_s = -lam_sq_s - cor_s
        cen_s[0] += sigma * mu
        dw, dt, dz, dsl, dss, dyl, dys = newton(
            d, sc, fac, -gw, -gt, -gz, -ryl, -rys, -lam_sq_l - dsl * dyl + sigma * mu,
            cen_s, refine)
        alpha_p = min(1.0, STEP * min(
            max_step_lin(sl, dsl), max_step_lin(yl, dyl),
            max_step_soc(ss, dss), max_step_soc(ys, dys)))
        if not (math.isfinite(alpha_p) and alpha_p > 0.0):
            status = NUMERICAL_ERROR
            break
        # The closed-form step to the boundary can be off by rounding for nearly degenerate
        # cones; halve the step until every cone is strictly interior.
        inside = False
        ss_new, ys_new = ss, ys
        for _ in range(30):
            ss_new, ys_new = ss + alpha_p * dss, ys + alpha_p * dys
            if interior_soc(ss_new) and interior_soc(ys_new):
                inside = True
                break
            alpha_p *= 0.5
        if not inside:
            status = NUMERICAL_ERROR
            break
        w += alpha_p * dw
        t += alpha_p * dt
        z += alpha_p * dz
        sl += alpha_p * dsl
        ss = ss_new
        yl += alpha_p * dyl
        ys = ys_new
    return w, yl, it, status

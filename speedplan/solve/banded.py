"""Structure-exploiting interior-point solver for the SOCP relaxation (O(n) per iteration).

The relaxation (paper eq. ``relax``, our :func:`~speedplan.solve.clarabel_.build_socp`) is

    minimise   Σ t_i
    subject to (w_{i+1} - w_i) <= A_i h_i,   (w_i - w_{i+1}) <= D_i h_i,   w_i <= w_max_i,
               ±(τ_i / J_i) w''_i - t_i <= 0            (rows with finite ``J_i`` only),
               z_i² <= w_i,   t_i z_i >= τ_i            (two 3-D second-order cones),
               w_0 = w_start,   w_{n-1} = w_end,

over ``x = (w, t, z)`` restricted to the ``m = n - 2`` interior nodes: the fixed end values are
eliminated and move to the right-hand side. We solve it with a Mehrotra predictor–corrector
primal–dual method with Nesterov–Todd scaling, in the form (and with the notation) of
CVXOPT's ``coneqp``: ``G x + s = b``, ``s ∈ K``, ``G' y + c = 0``, ``y ∈ K``.

Every Newton step reduces to the normal equations ``G' W⁻² G Δx = r``. Their matrix couples
node ``i`` only with ``i ± 1`` through the acceleration rows and with ``i ± 2`` through the
second difference of the jerk rows; ``t_i`` and ``z_i`` appear only in rows of node ``i``. So
we eliminate the 2×2 block of ``(t_i, z_i)`` per node (a closed-form Schur complement) and are
left with a pentadiagonal symmetric positive-definite system in ``w``, factored once per
iteration with :func:`scipy.linalg.cholesky_banded` and solved twice (predictor and
corrector). Assembly, scaling and step lengths are vectorised numpy over nodes, so an
iteration costs O(n) time and memory.

The problem is solved in internal units (``w`` scaled to at most 1, ``s`` to unit mean step),
with every variable further scaled per node from the O(n) no-jerk profile ``w_ref``
(``w = w_ref ŵ``, ``z = sqrt(w_ref) ẑ``, ``t = τ / sqrt(w_ref) t̂``) so that every node's cones
become the same unit cones ``ẑ² <= ŵ`` and ``t̂ ẑ >= 1``, and jerk rows are normalised. The
start is CVXOPT's default (least-squares primal, least-norm dual, shifted into the cones);
each Newton solve gets one round of iterative refinement once the gap is small.

Near the optimum the NT scaling becomes ill-conditioned and rounding can stop progress a
little short of ``tol`` (seen with strongly varying ``J``). The method then reports
``status="AlmostSolved"`` (as Clarabel does) if the certified relative gap below is at most
1e-6 and ``w`` is feasible, and raises :class:`~speedplan.errors.SolverError` otherwise.

The returned ``dual_objective`` is a rigorous lower bound, independent of how well the
iterates satisfy the dual equations: the Lagrangian of the relaxation with the solver's
multipliers of the acceleration and jerk rows (scaled so that the jerk multipliers of each
node sum to at most 1, which makes the Lagrangian independent of ``t``) is minimised in
closed form over the box ``0 <= w <= w_max``, node by node. The ``primal_objective`` is
``Σ max(τ_i / sqrt(w_i), τ_i |w''_i| / J_i)`` at the returned ``w``, i.e. the best ``t`` for it.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.linalg import LinAlgError, cho_solve_banded, cholesky_banded

from .._checks import FloatArray
from ..errors import InfeasibleError, SolverError
from .clarabel_ import RelaxationResult
from .nojerk import check_reachable, max_feasible_w
from .problem import DiscreteProblem

__all__ = ["solve_relaxation_banded"]

#: Fraction of the step to the cone boundary taken per iteration.
_STEP = 0.99
#: Exponent of Mehrotra's centring heuristic ``σ = (1 - α_affine)^3``.
_SIGMA_EXPONENT = 3.0
#: Rounds of iterative refinement of each Newton solve (see :func:`_newton`).
_REFINE_STEPS = 1
#: Relative gap below which Newton solves are refined.
_REFINE_BELOW = 1e-3


@dataclass(frozen=True)
class _Data:
    """Problem data in internal units, flattened for vectorised use.

    Linear rows are stored in one vector in the order: acceleration (n-1), braking (n-1),
    upper bounds (m), positive jerk rows (k), negative jerk rows (k); ``k`` counts the nodes
    with finite ``J``, listed in ``jk``.
    """

    m: int
    d0: FloatArray  # second-difference weights of w_{i-1}, w_i, w_{i+1}, shape (m,)
    d1: FloatArray
    d2: FloatArray
    jk: NDArray[np.intp]  # interior nodes with finite J
    cj: FloatArray  # τ_i / J_i at those nodes
    tau: FloatArray  # interior cell lengths, shape (m,)
    b_lin: FloatArray  # right-hand side of the linear rows
    w_full_const: FloatArray  # (n,) zeros with the fixed end values in place
    w_max: FloatArray  # interior upper bounds
    n_lin: int
    jconst: FloatArray  # second difference of the fixed end values at jerk nodes
    row: FloatArray  # scale of each linear row (jerk rows normalised to unit norm)
    cw: FloatArray  # column scales: w = cw ŵ, t = ct t̂ (and z = sqrt(cw) ẑ)
    ct: FloatArray


def _prepare(p: DiscreteProblem, w_ref: FloatArray) -> _Data:
    """Flatten the (already scaled) problem into the arrays the iteration uses.

    Variables are scaled per node, ``w = cw ŵ``, ``z = sqrt(cw) ẑ``, ``t = ct t̂`` with
    ``cw = w_ref`` and ``ct = τ / sqrt(cw)``, which turns both cones of every node into the
    same unit cones ``ẑ² <= ŵ`` and ``t̂ ẑ >= 1``; the acceleration rows get the coefficients
    ``cw`` and the jerk rows are divided by ``ct``.
    """
    n = p.n
    m = n - 2
    h0, h1 = p.h[:-1], p.h[1:]
    d0 = 2.0 / (h0 * (h0 + h1))
    d1 = -2.0 / (h0 * h1)
    d2 = 2.0 / (h1 * (h0 + h1))
    cw = w_ref
    ct = p.tau / np.sqrt(cw)
    cwp = np.concatenate(([0.0], cw, [0.0]))
    jk = np.flatnonzero(np.isfinite(p.jerk))
    cj = p.tau[jk] / p.jerk[jk] / ct[jk]
    w_const = np.zeros(n)
    w_const[0], w_const[-1] = p.w_start, p.w_end
    # G x + s = b with the fixed ends moved to b: b = bound - (row applied to the fixed ends).
    dconst = np.diff(w_const)
    jconst = (d0 * w_const[:-2] + d1 * w_const[1:-1] + d2 * w_const[2:])[jk] * cj
    b_lin = np.concatenate(
        (
            p.accel * p.h - dconst,
            p.decel * p.h + dconst,
            p.w_max[1:-1] / cw,
            -jconst,
            jconst,
        )
    )
    dh0, dh1, dh2 = d0 * cwp[:-2], d1 * cw, d2 * cwp[2:]
    # Jerk rows may still carry large coefficients; normalising them balances the starting
    # point and the stopping tests.
    row = np.ones(b_lin.size)
    jnorm = 1.0 / np.sqrt(cj**2 * (dh0[jk] ** 2 + dh1[jk] ** 2 + dh2[jk] ** 2) + 1.0)
    row[2 * (n - 1) + m :] = np.concatenate((jnorm, jnorm))
    b_lin = b_lin * row
    return _Data(
        row=row, cw=cw, ct=ct,
        m=m, d0=dh0, d1=dh1, d2=dh2, jk=jk, cj=cj, tau=np.ones(m), b_lin=b_lin,
        w_full_const=w_const, w_max=p.w_max[1:-1] / cw, n_lin=b_lin.size,
        jconst=jconst,
    )


# --- the constraint map G and its adjoint -------------------------------------------------


def _second_diff(d: _Data, w: FloatArray) -> FloatArray:
    """``D̂ w``: second difference of interior ``w`` with zero end values, shape (m,)."""
    wp = np.concatenate(([0.0], w, [0.0]))
    out: FloatArray = d.d0 * wp[:-2] + d.d1 * wp[1:-1] + d.d2 * wp[2:]
    return out


def _second_diff_t(d: _Data, u: FloatArray) -> FloatArray:
    """``D̂' u`` for node values ``u`` (m,)."""
    full = np.zeros(d.m + 2)
    full[:-2] += d.d0 * u
    full[1:-1] += d.d1 * u
    full[2:] += d.d2 * u
    return full[1:-1]


def _g_lin(d: _Data, w: FloatArray, t: FloatArray) -> FloatArray:
    """Linear rows of ``G x`` (no constants)."""
    dw = np.diff(np.concatenate(([0.0], d.cw * w, [0.0])))
    jw = d.cj * _second_diff(d, w)[d.jk]
    tj = t[d.jk]
    out: FloatArray = d.row * np.concatenate((dw, -dw, w, jw - tj, -jw - tj))
    return out


def _g_soc(w: FloatArray, t: FloatArray, z: FloatArray) -> FloatArray:
    """Cone rows of ``G x`` (no constants), shape (3, 2m): node cones then ``t z`` cones."""
    return -np.stack(
        (np.concatenate((w, t + z)), np.concatenate((2.0 * z, t - z)),
         np.concatenate((w, np.zeros_like(w))))
    )


def _g_adjoint(
    d: _Data, yl: FloatArray, ys: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``G' y`` split into its ``w``, ``t`` and ``z`` parts."""
    m, nl, k = d.m, d.m + 1, d.jk.size
    yl = yl * d.row
    acc = yl[:nl] - yl[nl : 2 * nl]
    ub = yl[2 * nl : 2 * nl + m]
    jp, jm = yl[2 * nl + m : 2 * nl + m + k], yl[2 * nl + m + k :]
    u = np.zeros(m)
    u[d.jk] = d.cj * (jp - jm)
    y1, y2 = ys[:, :m], ys[:, m:]
    gw = d.cw * (acc[:-1] - acc[1:]) + ub + _second_diff_t(d, u) - y1[0] - y1[2]
    gt = -(y2[0] + y2[1])
    gt[d.jk] -= jp + jm
    gz = -2.0 * y1[1] - y2[0] + y2[1]
    return gw, gt, gz


# --- second-order cone algebra (3-D cones stored column-wise, shape (3, K)) ---------------


def _jdot(u: FloatArray, v: FloatArray) -> FloatArray:
    """``u' J v`` per cone with ``J = diag(1, -1, -1)``."""
    out: FloatArray = u[0] * v[0] - u[1] * v[1] - u[2] * v[2]
    return out


def _jnorm2(u: FloatArray) -> FloatArray:
    """``u' J u`` per cone, computed as ``(u_0 - |u_a|)(u_0 + |u_a|) - u_b²``.

    ``a`` is the larger of the two other components. Near the cone boundary the plain
    ``u_0² - u_1² - u_2²`` cancels to the square of the largest entry; pairing ``u_0`` with the
    largest entry first keeps the error relative to the smaller one (for ``z² <= w`` with
    small ``w`` that is ``4 (w - z²)`` accurate to ``w`` instead of to 1).
    """
    a1, a2 = np.abs(u[1]), np.abs(u[2])
    big = np.maximum(a1, a2)
    small = np.minimum(a1, a2)
    out: FloatArray = (u[0] - big) * (u[0] + big) - small * small
    return out


def _jordan(u: FloatArray, v: FloatArray) -> FloatArray:
    """Jordan product ``u ∘ v = (u'v, u_0 v̄ + v_0 ū)`` per cone."""
    return np.stack((u[0] * v[0] + u[1] * v[1] + u[2] * v[2],
                     u[0] * v[1] + v[0] * u[1], u[0] * v[2] + v[0] * u[2]))


def _jordan_solve(lam: FloatArray, b: FloatArray) -> FloatArray:
    """Solve ``lam ∘ u = b`` for ``u`` per cone."""
    u0 = (lam[0] * b[0] - lam[1] * b[1] - lam[2] * b[2]) / _jnorm2(lam)
    return np.stack((u0, (b[1] - u0 * lam[1]) / lam[0], (b[2] - u0 * lam[2]) / lam[0]))


def _max_step_soc(u: FloatArray, du: FloatArray) -> float:
    """Largest ``α`` with ``u + α du`` in every cone (``u`` interior); ``inf`` if unbounded."""
    a = _jnorm2(du)
    b = _jdot(u, du)
    c = _jnorm2(u)
    disc = b * b - a * c
    # Roots of a α² + 2 b α + c = 0; c > 0, the first positive root is where u + α du exits.
    sq = np.sqrt(np.maximum(disc, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        # Cancellation-free pair of roots: q / a and c / q with q = -(b + sign(b) sq).
        q = -(b + np.copysign(sq, b))
        r1 = q / a
        r2 = c / q
    big = np.inf
    r1 = np.where(np.isfinite(r1) & (r1 > 0), r1, big)
    r2 = np.where(np.isfinite(r2) & (r2 > 0), r2, big)
    root = np.minimum(r1, r2)
    # No real root with a > 0: the quadratic stays positive along the ray.
    root = np.where((disc < 0) & (a >= 0), big, root)
    # Also keep u_0 + α du_0 > 0 (the quadratic alone does not tell K from -K).
    with np.errstate(divide="ignore"):
        r0 = np.where(du[0] < 0, -u[0] / np.where(du[0] < 0, du[0], -1.0), big)
    return float(np.min(np.minimum(root, r0), initial=big))


def _interior_soc(u: FloatArray) -> bool:
    """Whether every cone of ``u`` is strictly interior."""
    return bool(np.all(u[0] > 0) and np.all(_jnorm2(u) > 0))


def _max_step_lin(u: FloatArray, du: FloatArray) -> float:
    """Largest ``α`` with ``u + α du >= 0`` (``u > 0``); ``inf`` if unbounded."""
    # min over du < 0 of -u/du is 1 / max(-du/u): one pass, no boolean indexing.
    worst = float(np.max(-du / u, initial=0.0))
    return 1.0 / worst if worst > 0.0 else float("inf")


def _min_eig_soc(u: FloatArray) -> float:
    """Smallest eigenvalue ``u_0 - ||ū||`` over the cones."""
    return float(np.min(u[0] - np.hypot(u[1], u[2]), initial=np.inf))


@dataclass(frozen=True)
class _Scaling:
    """Nesterov–Todd scaling ``W`` at the current ``(s, y)``."""

    wl: FloatArray  # linear: W = diag(sqrt(s / y))
    beta: FloatArray  # cones: W = β (2 v v' - J)
    v: FloatArray
    wbar: FloatArray  # scaling point with wbar' J wbar = 1: W² = β² (2 wbar wbar' - J)
    lam_l: FloatArray  # scaled point λ = W y = W⁻¹ s
    lam_s: FloatArray


def _scaling(sl: FloatArray, yl: FloatArray, ss: FloatArray, ys: FloatArray) -> _Scaling:
    """Compute the NT scaling of every cone (formulas of CVXOPT's ``misc.compute_scaling``)."""
    wl = np.sqrt(sl / yl)
    sn = np.sqrt(_jnorm2(ss))
    yn = np.sqrt(_jnorm2(ys))
    beta = np.sqrt(sn / yn)
    sb = ss / sn
    yb = ys / yn
    gamma = np.sqrt(0.5 * (1.0 + (sb * yb).sum(axis=0)))
    wbar = np.stack((sb[0] + yb[0], sb[1] - yb[1], sb[2] - yb[2])) / (2.0 * gamma)
    v = wbar.copy()
    v[0] += 1.0
    v /= np.sqrt(2.0 * (wbar[0] + 1.0))
    sc = _Scaling(wl=wl, beta=beta, v=v, wbar=wbar, lam_l=np.sqrt(sl * yl), lam_s=ys)
    return _Scaling(wl=wl, beta=beta, v=v, wbar=wbar, lam_l=sc.lam_l, lam_s=_apply_w(sc, ys))


def _apply_w(sc: _Scaling, u: FloatArray) -> FloatArray:
    """``W u`` on the cone part."""
    vu = (sc.v * u).sum(axis=0)
    out = 2.0 * vu * sc.v
    out[0] -= u[0]
    out[1:] += u[1:]
    result: FloatArray = sc.beta * out
    return result


def _apply_winv(sc: _Scaling, u: FloatArray) -> FloatArray:
    """``W⁻¹ u`` on the cone part: ``W⁻¹ = (2 Jv (Jv)' - J) / β``."""
    jv = sc.v * np.array([[1.0], [-1.0], [-1.0]])
    vu = (jv * u).sum(axis=0)
    out = 2.0 * vu * jv
    out[0] -= u[0]
    out[1:] += u[1:]
    result: FloatArray = out / sc.beta
    return result


def _hessian_entries(sc: _Scaling) -> tuple[FloatArray, ...]:
    """Return entries 00, 01, 02, 11, 12, 22 of ``H = W⁻² = (2 ŵ ŵ' - J) / β²``, ``ŵ = J wbar``."""
    u0, u1, u2 = sc.wbar[0], -sc.wbar[1], -sc.wbar[2]
    ib2 = 1.0 / (sc.beta * sc.beta)
    return (
        (2.0 * u0 * u0 - 1.0) * ib2,
        2.0 * u0 * u1 * ib2,
        2.0 * u0 * u2 * ib2,
        (2.0 * u1 * u1 + 1.0) * ib2,
        2.0 * u1 * u2 * ib2,
        (2.0 * u2 * u2 + 1.0) * ib2,
    )


# --- the reduced (pentadiagonal) Newton system --------------------------------------------


@dataclass(frozen=True)
class _Factor:
    """Cholesky factor of the reduced matrix and the per-node 2×2 elimination data."""

    chol: FloatArray
    hl: FloatArray  # linear-row weights y / s
    hs: tuple[FloatArray, ...]  # cone Hessian entries
    a: FloatArray  # coupling of t_i to D̂_i w (m,), zero where J = inf
    bwz: FloatArray  # coupling of z_i to w_i
    p: FloatArray  # inverse of the (t, z) block: [[p, q], [q, r]]
    q: FloatArray
    r: FloatArray


def _factor(d: _Data, hs: tuple[FloatArray, ...], hl: FloatArray) -> _Factor:
    """Assemble the Schur complement in ``w`` of ``G' H G`` and factor it (banded Cholesky).

    ``hl`` are the weights of the linear rows and ``hs`` the entries of the cones' 3×3 blocks
    of ``H`` (see :func:`_hessian_entries`).
    """
    m, nl, k = d.m, d.m + 1, d.jk.size
    h00, h01, h02, h11, h12, h22 = (x[:m] for x in hs)  # cones z² <= w
    g00, g01, _, g11, _, _ = (x[m:] for x in hs)  # cones t z >= τ
    hl_rows = hl
    hl = hl * d.row**2  # weights of the unscaled rows
    hp = hl[2 * nl + m : 2 * nl + m + k]
    hm = hl[2 * nl + m + k :]
    # (t, z) block per node.
    mtt = g00 + 2.0 * g01 + g11
    mtt_cone = mtt.copy()
    mtt[d.jk] += hp + hm
    mzz = 4.0 * h11 + g00 - 2.0 * g01 + g11
    mtz = g00 - g11
    bwz = 2.0 * (h01 + h12)
    a = np.zeros(m)
    a[d.jk] = -d.cj * (hp - hm)
    det = mtt * mzz - mtz * mtz
    p, q, r = mzz / det, -mtz / det, mtt / det
    # Jerk weight after eliminating t: c²(H⁺ + H⁻) - p a², written without cancellation as
    # c² (4 H⁺H⁻ + κ (H⁺ + H⁻)) / (H⁺ + H⁻ + κ) with κ the cones' own Schur weight of t.
    kappa = (mtt_cone - mtz * mtz / mzz)[d.jk]
    hsum = hp + hm
    e = np.zeros(m)
    e[d.jk] = d.cj**2 * (4.0 * hp * hm + kappa * hsum) / (hsum + kappa)
    f = -q * a * bwz
    dg = hl[2 * nl : 2 * nl + m] + (h00 + 2.0 * h02 + h22) - r * bwz * bwz
    gacc = hl[:nl] + hl[nl : 2 * nl]
    cw = d.cw
    # Pentadiagonal upper storage: ab[2] diagonal, ab[1, j] = S[j-1, j], ab[0, j] = S[j-2, j].
    diag = np.zeros(m + 2)
    diag[:-2] += e * d.d0**2
    diag[1:-1] += e * d.d1**2 + 2.0 * f * d.d1 + dg
    diag[2:] += e * d.d2**2
    off1 = np.zeros(m + 1)  # pairs of padded nodes (p, p + 1)
    off1[:-1] += d.d0 * (e * d.d1 + f)
    off1[1:] += d.d2 * (e * d.d1 + f)
    off2 = np.zeros(m)  # pairs (p, p + 2)
    off2 += e * d.d0 * d.d2
    ab = np.zeros((3, m))
    ab[2] = diag[1:-1] + cw * cw * (gacc[:-1] + gacc[1:])
    if m > 1:
        ab[1, 1:] = off1[1:-1] - cw[:-1] * cw[1:] * gacc[1:-1]
    if m > 2:
        ab[0, 2:] = off2[1:-1]
    chol = cholesky_banded(ab, lower=False, check_finite=False)
    return _Factor(chol=chol, hl=hl_rows, hs=hs, a=a, bwz=bwz, p=p, q=q, r=r)


def _solve_normal(
    d: _Data, fac: _Factor, rw: FloatArray, rt: FloatArray, rz: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Solve ``G' H G Δx = r`` by eliminating ``(t, z)`` node by node."""
    rho_t = fac.p * rt + fac.q * rz
    rho_z = fac.q * rt + fac.r * rz
    rhs = rw - _second_diff_t(d, fac.a * rho_t) - fac.bwz * rho_z
    dw = cho_solve_banded((fac.chol, False), rhs, check_finite=False)
    ct = fac.a * _second_diff(d, dw)
    cz = fac.bwz * dw
    dt = rho_t - (fac.p * ct + fac.q * cz)
    dz = rho_z - (fac.q * ct + fac.r * cz)
    return dw, dt, dz


def _apply_h_soc(hs: tuple[FloatArray, ...], u: FloatArray) -> FloatArray:
    h00, h01, h02, h11, h12, h22 = hs
    return np.stack((h00 * u[0] + h01 * u[1] + h02 * u[2],
                     h01 * u[0] + h11 * u[1] + h12 * u[2],
                     h02 * u[0] + h12 * u[1] + h22 * u[2]))


def _newton(
    d: _Data,
    sc: _Scaling,
    fac: _Factor,
    bx: tuple[FloatArray, FloatArray, FloatArray],
    byl: FloatArray,
    bys: FloatArray,
    bsl: FloatArray,
    bss: FloatArray,
    refine: int = _REFINE_STEPS,
) -> tuple[tuple[FloatArray, FloatArray, FloatArray], FloatArray, FloatArray, FloatArray,
           FloatArray]:
    """Solve ``G'Δy = bx``, ``GΔx + Δs = by``, ``λ ∘ (WΔy + W⁻¹Δs) = bs``.

    Returns ``Δx, Δs (lin, cone), Δy (lin, cone)``.
    """
    ul = bsl / sc.lam_l
    us = _jordan_solve(sc.lam_s, bss)
    # v = H by - W⁻¹ u; then (G'HG) Δx = bx + G' v and Δy = H G Δx - v.
    vl = fac.hl * byl - ul / sc.wl
    vs = _apply_h_soc(fac.hs, bys) - _apply_winv(sc, us)
    gw, gt, gz = _g_adjoint(d, vl, vs)
    dw, dt, dz = _solve_normal(d, fac, bx[0] + gw, bx[1] + gt, bx[2] + gz)
    gl = _g_lin(d, dw, dt)
    gs = _g_soc(dw, dt, dz)
    dyl = fac.hl * gl - vl
    dys = _apply_h_soc(fac.hs, gs) - vs
    # The last two equations hold by construction; only G'Δy = bx inherits the rounding of
    # the reduced solve, which grows as H becomes ill-conditioned near the optimum. A round of
    # iterative refinement with the same factor restores it (δy = H G δx, δs = -G δx).
    for _ in range(refine):
        ew, et, ez = _g_adjoint(d, dyl, dys)
        ew, et, ez = bx[0] - ew, bx[1] - et, bx[2] - ez
        cw, ct, cz = _solve_normal(d, fac, ew, et, ez)
        cl = _g_lin(d, cw, ct)
        cs = _g_soc(cw, ct, cz)
        dw, dt, dz = dw + cw, dt + ct, dz + cz
        gl, gs = gl + cl, gs + cs
        dyl = dyl + fac.hl * cl
        dys = dys + _apply_h_soc(fac.hs, cs)
    return (dw, dt, dz), byl - gl, bys - gs, dyl, dys


# --- certificates -------------------------------------------------------------------------


def _primal_t(p: DiscreteProblem, w: FloatArray) -> FloatArray:
    """Smallest feasible ``t`` for the full ``w`` (interior ``w > 0``)."""
    t: FloatArray = p.tau / np.sqrt(w[1:-1])
    finite = np.isfinite(p.jerk)
    wpp = p.second_difference @ w
    t[finite] = np.maximum(t[finite], p.tau[finite] * np.abs(wpp[finite]) / p.jerk[finite])
    return t


def _lagrangian_bound(
    p: DiscreteProblem, mu_acc: FloatArray, mu_dec: FloatArray, nu_p: FloatArray,
    nu_m: FloatArray,
) -> float:
    """Lower bound from multipliers of the acceleration and jerk rows (weak duality).

    With ``μ >= 0`` on the rows ``±(w_{k+1} - w_k) <= A_k h_k`` and ``ν± >= 0`` (per node,
    zero where ``J = inf``) on ``±τ w'' / J - t <= 0``, the multiplier ``λ = 1 - ν⁺ - ν⁻ >= 0``
    of ``t >= τ / sqrt(w)`` makes the Lagrangian free of ``t``; its minimum over the box
    ``0 <= w <= w_max`` is separable and closed-form. Any such multipliers give a valid bound.
    """
    mu_acc, mu_dec = np.maximum(mu_acc, 0.0), np.maximum(mu_dec, 0.0)
    nu_p, nu_m = np.maximum(nu_p, 0.0), np.maximum(nu_m, 0.0)
    excess = np.maximum(nu_p + nu_m, 1.0)  # λ >= 0 needs ν⁺ + ν⁻ <= 1
    nu_p, nu_m = nu_p / excess, nu_m / excess
    lam = 1.0 - nu_p - nu_m
    finite = np.isfinite(p.jerk)
    coef = np.where(finite, (nu_p - nu_m) * p.tau / np.where(finite, p.jerk, 1.0), 0.0)
    # Linear coefficient of the full w in the Lagrangian.
    net = mu_acc - mu_dec
    g = np.zeros(p.n)
    g[1:] += net
    g[:-1] -= net
    g += p.second_difference.T @ coef
    const = (g[0] * p.w_start + g[-1] * p.w_end
             - float(mu_acc @ (p.accel * p.h)) - float(mu_dec @ (p.decel * p.h)))
    gi, c, wmax = g[1:-1], lam * p.tau, p.w_max[1:-1]
    pos = gi > 0
    w_opt = wmax.copy()
    w_opt[pos] = np.minimum((c[pos] / (2.0 * gi[pos])) ** (2.0 / 3.0), wmax[pos])
    val = gi * w_opt
    cpos = c > 0
    if np.any(cpos & (w_opt <= 0)):
        return -np.inf
    val[cpos] += c[cpos] / np.sqrt(w_opt[cpos])
    return float(const + val.sum())


def _row_multipliers(d: _Data, yl: FloatArray) -> tuple[FloatArray, ...]:
    """Multipliers of the scaled problem's own rows from those of the internal rows."""
    m, nl, k = d.m, d.m + 1, d.jk.size
    y = yl * d.row
    nu_p, nu_m = np.zeros(m), np.zeros(m)
    nu_p[d.jk] = y[2 * nl + m : 2 * nl + m + k] / d.ct[d.jk]
    nu_m[d.jk] = y[2 * nl + m + k :] / d.ct[d.jk]
    return y[:nl], y[nl : 2 * nl], nu_p, nu_m


# --- driver --------------------------------------------------------------------------------


def _scales(problem: DiscreteProblem, w_feasible: FloatArray) -> tuple[float, float]:
    """Return ``(s_scale, w_scale)`` of the internal units: ``w`` up to 1 and unit mean step."""
    w_scale = float(np.max(w_feasible))
    s_scale = float(np.mean(problem.h))
    return s_scale, w_scale


def _check_feasible(problem: DiscreteProblem) -> FloatArray:
    """Raise :class:`InfeasibleError` unless some ``w`` with ``w_i > 0`` inside meets the rows.

    The jerk rows never make the relaxation infeasible (``t`` may grow), so feasibility is
    that of the linear rows with strictly positive interior ``w``: the O(n) no-jerk pass.
    """
    check_reachable(problem)
    wmf = max_feasible_w(problem)
    inner = wmf[1:-1]
    if inner.size and float(np.min(inner)) <= 0.0:
        i = int(np.argmin(inner)) + 1
        raise InfeasibleError(
            f"the relaxation is infeasible: no speed law with w > 0 at s={problem.s[i]:.6g} "
            "meets the speed bound and the acceleration bounds",
            constraint="w_max",
            s=float(problem.s[i]),
        )
    return wmf


@dataclass(frozen=True)
class _Outcome:
    """Final iterate of :func:`_iterate` in internal units."""

    w: FloatArray
    yl: FloatArray
    iterations: int
    status: str


def _b_soc(d: _Data) -> FloatArray:
    """Constant part of the cone rows: ``(1, 0, -1)`` and ``(0, 0, 2 sqrt(τ))``."""
    b = np.zeros((3, 2 * d.m))
    b[0, : d.m] = 1.0
    b[2, : d.m] = -1.0
    b[2, d.m :] = 2.0 * np.sqrt(d.tau)
    return b


def _shift_into_cone(ul: FloatArray, us: FloatArray) -> None:
    """CVXOPT's initial-point rule: add ``(1 + t) e`` when ``u`` is not interior by margin."""
    ts = -min(float(np.min(ul, initial=np.inf)), _min_eig_soc(us))
    nrm = np.sqrt(float(ul @ ul) + float((us * us).sum()))
    if ts >= -1e-8 * max(nrm, 1.0):
        ul += 1.0 + ts
        us[0] += 1.0 + ts


def _iterate(d: _Data, tol: float, max_iter: int) -> _Outcome:
    """Mehrotra predictor–corrector iterations from CVXOPT's default starting point."""
    m = d.m
    b_lin, b_soc = d.b_lin, _b_soc(d)
    nu = d.n_lin + 2 * m  # barrier degree: one per linear row and per cone
    ones, zeros = np.ones(2 * m), np.zeros(2 * m)
    fac = _factor(d, (ones, zeros, zeros, ones, zeros, ones), np.ones(d.n_lin))
    # CVXOPT's default start: least-squares x of G x = b, least-norm y of G' y = -c, both
    # shifted into the cones.
    w, t, z = _solve_normal(d, fac, *_g_adjoint(d, b_lin, b_soc))
    sl = b_lin - _g_lin(d, w, t)
    ss = b_soc - _g_soc(w, t, z)
    uw, ut, uz = _solve_normal(d, fac, np.zeros(m), -d.ct, np.zeros(m))
    yl = _g_lin(d, uw, ut)
    ys = _g_soc(uw, ut, uz)
    _shift_into_cone(sl, ss)
    _shift_into_cone(yl, ys)
    res_x0 = max(1.0, np.sqrt(m))
    res_y0 = max(1.0, np.sqrt(float(b_lin @ b_lin) + float((b_soc * b_soc).sum())))
    e_soc = np.zeros((3, 2 * m))
    e_soc[0] = 1.0
    status = "MaxIterations"
    it = 0
    best_gap, stalled = np.inf, 0
    for it in range(max_iter + 1):
        gw, gt, gz = _g_adjoint(d, yl, ys)
        gt += d.ct
        ryl = _g_lin(d, w, t) + sl - b_lin
        rys = _g_soc(w, t, z) + ss - b_soc
        pcost = float(d.ct @ t)
        dcost = -float(yl @ b_lin) - float((ys * b_soc).sum())
        gap = float(sl @ yl) + float((ss * ys).sum())
        pres = np.sqrt(float(ryl @ ryl) + float((rys * rys).sum())) / res_y0
        dres = np.sqrt(float(gw @ gw) + float(gt @ gt) + float(gz @ gz)) / res_x0
        relgap = gap / max(min(abs(pcost), abs(dcost)), 1e-300)
        if pres <= tol and dres <= tol and relgap <= tol:
            status = "Solved"
            break
        # Near the optimum the NT scaling becomes ill-conditioned and rounding may stop
        # progress short of ``tol``; detect that instead of spinning to ``max_iter``.
        if relgap < 0.5 * best_gap:
            best_gap, stalled = relgap, 0
        else:
            stalled += 1
        if stalled >= _STALL_ITERATIONS and best_gap < _ALMOST_GAP:
            status = "Stalled"
            break
        if it == max_iter:
            break
        if not (np.isfinite(pres) and np.isfinite(dres) and np.isfinite(gap)):
            status = "NumericalError"
            break
        sc = _scaling(sl, yl, ss, ys)
        try:
            fac = _factor(d, _hessian_entries(sc), yl / sl)
        except LinAlgError:
            status = "NumericalError"
            break
        mu = gap / nu
        # Refinement only pays once the scaling is ill-conditioned, close to the optimum.
        refine = _REFINE_STEPS if relgap < _REFINE_BELOW else 0
        lam_sq_l = sc.lam_l * sc.lam_l
        lam_sq_s = _jordan(sc.lam_s, sc.lam_s)
        bx = (-gw, -gt, -gz)
        # Predictor (affine-scaling) direction.
        dx, dsl, dss, dyl, dys = _newton(
            d, sc, fac, bx, -ryl, -rys, -lam_sq_l, -lam_sq_s, refine)
        alpha = min(_max_step_lin(sl, dsl), _max_step_lin(yl, dyl),
                    _max_step_soc(ss, dss), _max_step_soc(ys, dys))
        sigma = (1.0 - min(1.0, alpha)) ** _SIGMA_EXPONENT
        # Corrector: second-order term and centring, same factorisation.
        cor_s = _jordan(_apply_winv(sc, dss), _apply_w(sc, dys))
        dx, dsl, dss, dyl, dys = _newton(
            d, sc, fac, bx, -ryl, -rys,
            -lam_sq_l - dsl * dyl + sigma * mu,
            -lam_sq_s - cor_s + sigma * mu * e_soc, refine,
        )
        alpha_p = alpha_d = min(1.0, _STEP * min(
            _max_step_lin(sl, dsl), _max_step_lin(yl, dyl),
            _max_step_soc(ss, dss), _max_step_soc(ys, dys)))
        if not (np.isfinite(alpha_p) and np.isfinite(alpha_d)) or min(alpha_p, alpha_d) <= 0:
            status = "NumericalError"
            break
        # The closed-form step to the boundary can be off by rounding for nearly degenerate
        # cones; halve the step until every cone is strictly interior.
        for _ in range(30):
            ss_new, ys_new = ss + alpha_p * dss, ys + alpha_d * dys
            if _interior_soc(ss_new) and _interior_soc(ys_new):
                break
            alpha_p *= 0.5
            alpha_d *= 0.5
        else:
            status = "NumericalError"
            break
        w = w + alpha_p * dx[0]
        t = t + alpha_p * dx[1]
        z = z + alpha_p * dx[2]
        sl = sl + alpha_p * dsl
        ss = ss_new
        yl = yl + alpha_d * dyl
        ys = ys_new
    return _Outcome(w=w, yl=yl, iterations=it, status=status)


#: Iterations without halving the relative gap after which the method is declared stalled.
_STALL_ITERATIONS = 5
#: Certified relative gap accepted (as status "AlmostSolved") when the method stalls.
_ALMOST_GAP = 1e-6


def solve_relaxation_banded(
    problem: DiscreteProblem, *, tol: float = 1e-9, max_iter: int = 100
) -> RelaxationResult:
    """Solve the SOCP relaxation with a banded primal–dual interior-point method.

    Parameters
    ----------
    problem : DiscreteProblem
        The discrete problem; any grid (uniform or not), ``n >= 3``.
    tol : float, optional
        Tolerance on the relative primal and dual residuals and on the relative duality gap.
    max_iter : int, optional
        Maximum number of interior-point iterations.

    Returns
    -------
    RelaxationResult
        ``w`` (n,) with the end values in place, the best ``t`` for it, ``primal_objective =
        Σ t``, ``dual_objective`` a certified lower bound on the relaxation's optimum,
        ``status="Solved"`` (residuals and gap within ``tol``) or ``"AlmostSolved"`` (the
        method stalled with a certified relative gap <= 1e-6).

    Raises
    ------
    InfeasibleError
        If no ``w`` with positive interior values meets the bounds and acceleration rows.
    SolverError
        If the method does not converge within ``max_iter`` iterations or breaks down
        numerically (``backend="banded"``; ``status`` says which).

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.solve.problem import DiscreteProblem
    >>> n = 50
    >>> p = DiscreteProblem(s=np.arange(n, dtype=float), w_max=np.full(n, 4.0),
    ...                     accel=np.full(n - 1, 0.5), decel=np.full(n - 1, 0.5),
    ...                     jerk=np.full(n - 2, 0.1))
    >>> res = solve_relaxation_banded(p)
    >>> res.status, bool(res.dual_objective <= res.primal_objective)
    ('Solved', True)

    """
    t_start = time.perf_counter()
    if problem.n < 3:
        raise SolverError("the relaxation needs n >= 3 grid nodes", backend="banded",
                          status="InvalidProblem")
    wmf = _check_feasible(problem)
    s_scale, w_scale = _scales(problem, wmf[1:-1])
    scaled = problem.scaled(s_scale, w_scale)
    d = _prepare(scaled, wmf[1:-1] / w_scale)
    t_setup = time.perf_counter()
    out = _iterate(d, tol, max_iter)
    obj_scale = s_scale / np.sqrt(w_scale)
    # Back to the scaled problem's units; clip rounding-level excursions past the bounds.
    w_sc = np.concatenate(([scaled.w_start], np.clip(out.w * d.cw, 0.0, scaled.w_max[1:-1]),
                           [scaled.w_end]))
    t = _primal_t(scaled, w_sc)
    w = w_sc * w_scale
    w[0], w[-1] = problem.w_start, problem.w_end
    primal = float(t.sum()) * obj_scale
    dual = _lagrangian_bound(scaled, *_row_multipliers(d, out.yl)) * obj_scale
    status = out.status
    if status != "Solved":
        # Like Clarabel's AlmostSolved: accepted only with a certified gap and feasible w.
        cert_gap = (primal - dual) / max(abs(primal), 1e-300)
        feasible = problem.linear_violation(w) <= _ALMOST_GAP * max(1.0, w_scale)
        if not (status == "Stalled" and cert_gap <= _ALMOST_GAP and feasible):
            raise SolverError(
                f"banded interior-point method stopped with status {status} after "
                f"{out.iterations} iterations (certified relative gap {cert_gap:.2e})",
                backend="banded",
                status=status,
            )
        status = "AlmostSolved"
    t_end = time.perf_counter()
    return RelaxationResult(
        w=w,
        t=t * obj_scale,
        primal_objective=primal,
        dual_objective=dual,
        status=status,
        iterations=out.iterations,
        solve_time=t_end - t_setup,
        setup_time=t_setup - t_start,
    )

"""Local refinement of the original (nonconvex) problem by a banded interior-point method.

The refinement NLP (minimise ``Σ τ_i / sqrt(w_i)`` under the acceleration rows, the bounds and
the jerk-type rows ``|c_i · w_{i-1:i+2}| sqrt(w_i) <= B_i``) couples only neighbouring nodes:
every row touches at most three consecutive ``w``. A primal-dual interior-point step on it
condenses, after eliminating the row slacks and the bound multipliers, to one symmetric
pentadiagonal system in the interior ``w`` (the Hessian of the Lagrangian is tridiagonal;
``J' Σ J`` adds one band on each side), which LAPACK's banded Cholesky (``dpbtrf``) factors
in ``O(n)``. IPOPT with MUMPS spends most of its time on the same systems as general sparse
ones (``docs/performance.md`` has the measurements).

The method is IPOPT's (Wächter & Biegler, Math. Program. 106, 2006, with its default
constants) on this structure: a slack for every row, the monotone barrier update, the filter
line search with second-order corrections, inertia correction by a multiple of the identity
(the condensed matrix must be positive definite) and a feasibility-restoration phase (the
elastic ``ℓ1`` problem with a proximity term) when the line search fails. The rows are the
plain ones, ``(c · w) sqrt(w_i) ∈ [-B_i, B_i]``. The answer is re-checked by the caller,
never trusted.

Each iteration's array work (rows, condensed matrix and its factor, direction, step rules,
errors, barrier) runs in compiled kernels (`speedplan.solve._banded_nlp_kernels`, numba)
once they are in numba's cache, and in the numpy methods below until then (a background
process compiles them meanwhile, see `nlp_kernels_ready`); the control flow is the same
code for both.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from itertools import pairwise
from types import ModuleType
from typing import Any, NamedTuple

import numpy as np

from ..core.checks import FloatArray, IntArray
from ..core.jit import FAMILIES
from .problem import DiscreteProblem

__all__ = ["KERNELS", "LATERAL_STARTS", "STARTS", "BandedNlpResult", "Start", "compile_nlp_kernels",
           "nlp_kernels_ready", "solve_banded_nlp"]

#: Lower bound on interior ``w`` (unit scale) when the problem has none: keeps ``sqrt(w)``
#: and ``1/sqrt(w)`` finite; it never binds at a solution (``1/sqrt(w)`` would be huge).
W_FLOOR = 1e-9
#: Relative width to which a fixed node (``w_min = w_max``) is opened so the barrier exists.
FIXED_WIDTH = 1e-10
#: Largest share of a node's own upper bound its lower bound takes where that bound lies under
#: `W_FLOOR` (the nodes of a stop of micrometres, ``w_max`` of 1e-12): such a node keeps its
#: room instead of being taken for a fixed one and opened by `FIXED_WIDTH` of the largest
#: bound, which let ``w`` there exceed its bound 3.5-fold and the plan's jerk 35-fold.
FLOOR_SHARE = 1e-3
#: Scaled optimality tolerance (IPOPT's ``tol``) and the one a run stalled by round-off may
#: stop at (IPOPT's ``acceptable_tol``); the caller checks the rows in any case.
TOL = 1e-9
ACCEPTABLE_TOL = 1e-6
#: A run whose best point so far is acceptable and whose last `STALL_ITERATIONS` steps were
#: each shorter than `STALL_STEP` (of the Newton step) has stalled by round-off: the error no
#: longer falls, and the run ends with that point. Over the 262 refinements of
#: ``benchmarks/bench_latency.py --plans 2000`` (seeds 5 and 11) this ended two runs, after 61
#: and 74 iterations instead of at the limit of 200, with the same point; no other run
#: changed.
STALL_STEP, STALL_ITERATIONS = 1e-2, 10
#: Iterations per run, restoration included: successful runs took at most 155 on the
#: benchmark corpus; runs that fail (a locally infeasible problem) would go on for hundreds.
MAX_ITER = 200
MAX_RESTORATIONS = 50
# IPOPT's algorithmic constants and defaults (same names).
KAPPA_EPS, KAPPA_MU, THETA_MU, TAU_MIN = 10.0, 0.2, 1.5, 0.99
GAMMA_THETA, GAMMA_PHI, DELTA, S_THETA, S_PHI, ETA_PHI = 1e-5, 1e-8, 1.0, 1.1, 2.3, 1e-8
ALPHA_MIN_FRAC = 0.05
KAPPA_SIGMA, MAX_SOC, KAPPA_SOC = 1e10, 4, 0.99
DELTA_W_FIRST, DELTA_W_MIN, DELTA_W_MAX = 1e-4, 1e-20, 1e40
KAPPA_W_PLUS_FIRST, KAPPA_W_PLUS, KAPPA_W_MINUS = 100.0, 8.0, 1.0 / 3.0
#: Restoration phase: penalty on the elastic variables and the reduction of the row
#: violation required before returning (IPOPT's resto_penalty_parameter, kappa_resto).
RESTO_RHO, KAPPA_RESTO = 1000.0, 0.9
#: Largest gradient entry after IPOPT's gradient-based scaling (nlp_scaling_max_gradient).
SCALING_MAX_GRADIENT = 100.0


@dataclass(frozen=True)
class Start:
    """How a run starts from the relaxed ``w``.

    Attributes
    ----------
    name : str
        Label used in statuses.
    mu_init : float
        First barrier parameter.
    push : float
        How far (relative) the start is moved into its bounds (IPOPT's ``bound_push`` and
        ``bound_frac``).
    gradient_scaling : bool
        IPOPT's gradient-based scaling of each row at the start.
    scale_objective : bool
        With ``gradient_scaling``, scale the objective too, as IPOPT does. Next to a
        standstill (the nodes next to a stop) the travel time's gradient grows as ``w^-1.5``:
        on two comfort plans this divided the objective by 4e5 and 3e7, the barrier term then
        outweighed it, the iterates left the relaxed point, and the runs ended in local
        optima 5e-5 and 1.3e-3 slower than the one next to it.
    """

    name: str
    mu_init: float
    push: float
    gradient_scaling: bool
    scale_objective: bool = True


#: The starts `speedplan.solve.refine.refine` runs, in this order, each a different path
#: to a local optimum (the problem is nonconvex). ``near`` and ``nearer`` stay close to the
#: relaxed ``w`` (small push, small first barrier parameter); ``ipopt-default`` is IPOPT's
#: default start and scaling, slower, and it reaches feasibility where the near starts stall.
#: On the benchmark corpus (150 instances) the best of the three was never worse than IPOPT
#: (defaults, tight tolerances) by more than 2.5e-5, and better by up to 3.4 %.
STARTS = (
    Start("near", mu_init=1e-2, push=1e-4, gradient_scaling=False),
    Start("ipopt-default", mu_init=0.1, push=1e-2, gradient_scaling=True),
    Start("nearer", mu_init=1e-3, push=1e-4, gradient_scaling=False),
)

#: The starts for problems with lateral-jerk (or yaw-rate) rows, in this order; the first
#: accepted one ends the refinement (`speedplan.solve.refine.refine`). ``rows-scaled`` scales
#: the rows as IPOPT does and the objective not at all (`Start`). Over the 262 refinements of
#: ``benchmarks/bench_latency.py --plans 2000`` (seeds 5 and 11) it was accepted on 259, each
#: time within 2e-7 of the best of seven starts, in a median of 48-49 iterations; the same
#: start scaling the objective too took 46-47 and ended more than 1e-4 slower on 22 of them
#: (up to 1.3e-3). ``near`` was as good but took 72-76; it answered where ``rows-scaled``
#: failed (those 3, and 1 of the 43 refinements of ``benchmarks/lateral_exactness.py --cases
#: 40``), and it and ``ipopt-default`` are the fallbacks.
LATERAL_STARTS = (
    Start("rows-scaled", mu_init=1e-2, push=1e-2, gradient_scaling=True, scale_objective=False),
    STARTS[0],
    STARTS[1],
    STARTS[2],
)


@dataclass(frozen=True)
class BandedNlpResult:
    """Raw result of `solve_banded_nlp` (``w`` on the full grid, problem units).

    Attributes
    ----------
    w : ndarray, shape (n,)
        Last (or best acceptable) iterate, ends included.
    status : str
        ``"Solved"``, ``"Acceptable"``, ``"MaxIterations"``, ``"LocallyInfeasible"``,
        ``"RestorationFailed"`` or ``"InertiaCorrectionFailed"``.
    success : bool
        ``status`` is ``"Solved"`` or ``"Acceptable"``.
    iterations, factorizations, restorations : int
        Counts (restoration iterations included in ``iterations``).
    """

    w: FloatArray
    status: str
    success: bool
    iterations: int
    factorizations: int
    restorations: int


@dataclass(frozen=True)
class _Family:
    """Rows ``r_k (c_k · w_{k:k+3}) sqrt(w_{k+1})`` on full-grid nodes ``k, k+1, k+2``.

    ``at(j)`` indexes the nodes ``k + j``: a slice when ``k`` is contiguous (the usual case,
    every row finite), which numpy serves without gathering.
    """

    k: IntArray
    c: FloatArray
    r: FloatArray

    def at(self, j: int) -> slice | IntArray:
        k = self.k
        if k[-1] - k[0] + 1 == k.size:
            return slice(int(k[0]) + j, int(k[-1]) + 1 + j)
        return k + j


class _Eval(NamedTuple):
    """Row values at one point and, per family, the stencil ``D (k, 3)``, ``c · w``, ``sqrt(w)``."""

    c: FloatArray
    stencils: list[tuple[FloatArray, FloatArray, FloatArray]]


class _Rows:
    """Acceleration rows (the first ``n - 1``), then every jerk-type family, in ``w[1:-1]``."""

    def __init__(self, p: DiscreteProblem) -> None:
        self.n = p.n
        self.w_start, self.w_end = p.w_start, p.w_end
        self.fams: list[_Family] = []
        lo, hi = [-p.decel * p.h], [p.accel * p.h]
        for fam in p.stencil_families():
            k = np.flatnonzero(np.isfinite(fam.bound))
            if k.size:
                self.fams.append(_Family(k=k, c=np.asarray(fam.coef, dtype=np.float64)[k],
                                         r=np.ones(k.size)))
                lo.append(-fam.bound[k])
                hi.append(fam.bound[k])
        self.lo, self.hi = np.concatenate(lo), np.concatenate(hi)
        self.size = self.lo.size

    def full(self, x: FloatArray) -> FloatArray:
        return np.concatenate(([self.w_start], x, [self.w_end]))

    def scale(self, ev: _Eval, max_gradient: float) -> None:
        """Scale each family row so its largest derivative at ``ev`` is ``<= max_gradient``."""
        lo, hi = [self.lo[: self.n - 1]], [self.hi[: self.n - 1]]
        o = self.n - 1
        fams = []
        for fa, (d, _, _) in zip(self.fams, ev.stencils, strict=True):
            k = fa.k.size
            sc = np.minimum(1.0, max_gradient / np.maximum(np.abs(d).max(axis=1), 1e-300))
            fams.append(_Family(k=fa.k, c=fa.c, r=fa.r * sc))
            lo.append(self.lo[o : o + k] * sc)
            hi.append(self.hi[o : o + k] * sc)
            o += k
        self.fams = fams
        self.lo, self.hi = np.concatenate(lo), np.concatenate(hi)

    def evaluate(self, x: FloatArray) -> _Eval:
        w = self.full(x)
        sx = np.sqrt(x)
        parts = [np.diff(w)]
        stencils = []
        for fa in self.fams:
            k0, k1, k2 = fa.at(0), fa.at(1), fa.at(2)
            sq = sx[k0]
            load = fa.c[:, 0] * w[k0] + fa.c[:, 1] * w[k1] + fa.c[:, 2] * w[k2]
            parts.append(fa.r * load * sq)
            d = np.empty((fa.k.size, 3))
            d[:, 0] = fa.r * fa.c[:, 0] * sq
            d[:, 1] = fa.r * (fa.c[:, 1] * sq + load / (2.0 * sq))
            d[:, 2] = fa.r * fa.c[:, 2] * sq
            stencils.append((d, load, sq))
        return _Eval(np.concatenate(parts), stencils)

    def jac_t(self, ev: _Eval, v: FloatArray) -> FloatArray:
        """``J' v`` (one value per interior node)."""
        out = np.zeros(self.n)
        va = v[: self.n - 1]
        out[1:] += va
        out[:-1] -= va
        o = self.n - 1
        for fa, (d, _, _) in zip(self.fams, ev.stencils, strict=True):
            vv = v[o : o + fa.k.size]
            out[fa.at(0)] += vv * d[:, 0]
            out[fa.at(1)] += vv * d[:, 1]
            out[fa.at(2)] += vv * d[:, 2]
            o += fa.k.size
        return out[1:-1]

    def jac(self, ev: _Eval, dx: FloatArray) -> FloatArray:
        """``J dx`` (one value per row)."""
        d = np.concatenate(([0.0], dx, [0.0]))
        parts = [np.diff(d)]
        for fa, (dd, _, _) in zip(self.fams, ev.stencils, strict=True):
            parts.append(dd[:, 0] * d[fa.at(0)] + dd[:, 1] * d[fa.at(1)] + dd[:, 2] * d[fa.at(2)])
        return np.concatenate(parts)

    def condensed(self, ev: _Eval, y: FloatArray, sig: FloatArray, diag: FloatArray) -> FloatArray:
        """``Σ_r y_r ∇²c_r + J' diag(sig) J + diag(diag)`` in LAPACK's lower band storage."""
        n = self.n
        dg, o1, o2 = np.zeros(n), np.zeros(n - 1), np.zeros(n - 2)
        sa = sig[: n - 1]
        dg[1:] += sa
        dg[:-1] += sa
        o1 -= sa
        o = n - 1
        for fa, (d, load, sq) in zip(self.fams, ev.stencils, strict=True):
            k0, k1, k2 = fa.at(0), fa.at(1), fa.at(2)
            s = sig[o : o + fa.k.size]
            yr = y[o : o + fa.k.size] * fa.r
            dg[k0] += s * d[:, 0] ** 2
            dg[k1] += s * d[:, 1] ** 2 + yr * (fa.c[:, 1] / sq - load / (4.0 * sq**3))
            dg[k2] += s * d[:, 2] ** 2
            o1[k0] += s * d[:, 0] * d[:, 1] + yr * fa.c[:, 0] / (2.0 * sq)
            o1[k1] += s * d[:, 1] * d[:, 2] + yr * fa.c[:, 2] / (2.0 * sq)
            o2[k0] += s * d[:, 0] * d[:, 2]
            o += fa.k.size
        ab = np.zeros((3, n - 2))
        ab[0] = dg[1:-1] + diag
        ab[1, :-1] = o1[1:-1]
        ab[2, :-2] = o2[1:-1]
        return ab


class _Objective(NamedTuple):
    """A separable objective: value, gradient and (diagonal) Hessian."""

    value: Callable[[FloatArray], float]
    grad: Callable[[FloatArray], FloatArray]
    hess: Callable[[FloatArray], FloatArray]


def _travel_time(tau: FloatArray) -> _Objective:
    """``Σ τ_i / sqrt(x_i)``."""
    return _Objective(
        value=lambda x: float(np.sum(tau / np.sqrt(x))),
        grad=lambda x: -0.5 * tau / (x * np.sqrt(x)),
        hess=lambda x: 0.75 * tau / (x * x * np.sqrt(x)),
    )


def _proximity_weights(x_ref: FloatArray, zeta: float) -> FloatArray:
    return zeta * np.minimum(1.0, 1.0 / np.abs(x_ref)) ** 2


def _proximity(x_ref: FloatArray, zeta: float) -> _Objective:
    """IPOPT's restoration objective without the penalty: ``ζ/2 ||D (x - x_ref)||²``."""
    d2 = _proximity_weights(x_ref, zeta)
    return _Objective(
        value=lambda x: 0.5 * _dot(d2, (x - x_ref) ** 2),
        grad=lambda x: d2 * (x - x_ref),
        hess=lambda x: d2,
    )


class _Point(NamedTuple):
    """Primal-dual iterate.

    ``x``, row slacks ``s``, elastic ``p, q`` (``c - s + p - q = 0``), row multipliers ``y``
    and the multipliers ``z`` of the stacked gaps (see ``_Phase``).
    """

    x: FloatArray
    s: FloatArray
    p: FloatArray
    q: FloatArray
    y: FloatArray
    z: FloatArray


class _Outcome(NamedTuple):
    status: str
    point: _Point
    mu: float
    filt: list[tuple[float, float]]
    iterations: int
    factorizations: int


def _dot(a: FloatArray, b: FloatArray) -> float:
    """``a · b`` without BLAS.

    A threaded ``ddot`` took a fifth of the run time when the cores were shared: handing the
    work to threads costs more than the sum itself.
    """
    return float(np.sum(a * b))


def _push_inside(v: FloatArray, lo: FloatArray, hi: FloatArray, push: float) -> FloatArray:
    """Clip into ``[lo, hi]`` and move away from each bound (IPOPT's bound_push, bound_frac)."""
    frac = push * (hi - lo)
    p_lo = np.minimum(push * np.maximum(1.0, np.abs(lo)), frac)
    p_hi = np.minimum(push * np.maximum(1.0, np.abs(hi)), frac)
    return np.clip(v, lo + p_lo, hi - p_hi)


def _max_step(v: FloatArray, dv: FloatArray, tau: float) -> float:
    """Largest ``α <= 1`` with ``v + α dv >= (1 - tau) v`` (fraction to the boundary)."""
    ratio = np.divide(-v, dv, out=np.full_like(v, np.inf), where=dv < 0)
    return float(min(1.0, tau * ratio.min()))


def _factor(ab: FloatArray, delta_last: float) -> tuple[FloatArray | None, float, int]:
    """Cholesky factor of ``ab`` (band storage), shifted by ``δ I`` if needed.

    A matrix that is not positive definite gets IPOPT's inertia correction; returns
    ``(factor, δ, factorizations)``.
    """
    from scipy.linalg.lapack import dpbtrf  # imported on first use: import speedplan stays light

    factor, info = dpbtrf(ab, lower=1)
    if info == 0:
        return factor, 0.0, 1
    count = 1
    delta = DELTA_W_FIRST if delta_last == 0 else max(DELTA_W_MIN, KAPPA_W_MINUS * delta_last)
    while delta <= DELTA_W_MAX:
        shifted = ab.copy()
        shifted[0] += delta
        factor, info = dpbtrf(shifted, lower=1)
        count += 1
        if info == 0:
            return factor, delta, count
        delta *= KAPPA_W_PLUS_FIRST if delta_last == 0 else KAPPA_W_PLUS
    return None, delta, count


class _Newton(NamedTuple):
    """The factored, condensed Newton system at one iterate (see ``_Phase.newton``)."""

    factor: FloatArray
    sig: FloatArray
    sig_s: FloatArray
    sig_e: FloatArray
    r_x: FloatArray
    r_s: FloatArray
    r_p: FloatArray
    r_q: FloatArray
    r_extra: FloatArray


class _Reference(NamedTuple):
    """What the filter line search compares a trial point with."""

    theta: float
    phi: float
    dphi: float
    mu: float
    theta_min: float
    theta_max: float
    filt: list[tuple[float, float]]


class _Trial(NamedTuple):
    point: _Point
    ev: _Eval
    residual: FloatArray


class _Phase:
    """One interior-point run on ``min f(x) + ρ Σ (p + q)``.

    The constraints are ``c(x) - s + p - q = 0``, ``lo <= s <= hi``, ``lb <= x <= ub`` and
    ``p, q >= 0``.

    The elastic ``p, q`` exist only when ``elastic`` (the restoration phase). All gaps to
    bounds are stacked as ``g = (x - lb, ub - x, s - lo, hi - s, p, q)`` with multipliers
    ``z``, so complementarity, the fraction to the boundary and the barrier are single vector
    operations. ``stop`` is asked after every accepted step; a status it returns ends the run.
    """

    def __init__(
        self, rows: _Rows, lb: FloatArray, ub: FloatArray, objective: _Objective, *,
        elastic: bool, rho: float = 0.0,
        stop: Callable[[_Eval, _Point], str | None] | None = None,
    ) -> None:
        self.rows, self.lb, self.ub, self.obj = rows, lb, ub, objective
        self.ne = rows.size if elastic else 0
        self.rho, self.stop = rho, stop
        m, r, e = lb.size, rows.size, self.ne
        self.m = m
        cuts = np.cumsum([0, m, m, r, r, e, e])
        self.slices = tuple(slice(a, b) for a, b in pairwise(cuts))

    def gaps(self, pt: _Point) -> FloatArray:
        lo, hi = self.rows.lo, self.rows.hi
        return np.concatenate((pt.x - self.lb, self.ub - pt.x, pt.s - lo, hi - pt.s, pt.p, pt.q))

    def residual(self, ev: _Eval | _FastEval, pt: _Point) -> FloatArray:
        r = ev.c - pt.s
        return r + pt.p - pt.q if self.ne else r

    def barrier(self, pt: _Point, g: FloatArray, mu: float) -> float:
        with np.errstate(invalid="ignore", divide="ignore"):
            logs = float(np.log(g).sum())
        return self.obj.value(pt.x) + self.rho * float(pt.p.sum() + pt.q.sum()) - mu * logs

    def errors(self, pt: _Point, ev: _Eval, g: FloatArray, jty: FloatArray,
               mu: float) -> tuple[float, float]:
        """IPOPT's scaled optimality error for ``mu = 0`` and for the current ``mu``."""
        i_xl, i_xu, i_sl, i_su, i_p, i_q = self.slices
        z, y = pt.z, pt.y
        dual = max(float(np.abs(self.obj.grad(pt.x) + jty - z[i_xl] + z[i_xu]).max()),
                   float(np.abs(-y - z[i_sl] + z[i_su]).max()))
        if self.ne:
            dual = max(dual, float(np.abs(self.rho + y - z[i_p]).max()),
                       float(np.abs(self.rho - y - z[i_q]).max()))
        z_sum = float(z.sum())
        s_d = max(1.0, (float(np.abs(y).sum()) + z_sum) / (100.0 * (self.m + y.size + g.size)))
        s_c = max(1.0, z_sum / (100.0 * g.size))
        rest = max(dual / s_d, float(np.abs(self.residual(ev, pt)).max()))
        gz = g * z
        return (max(rest, float(gz.max()) / s_c),
                max(rest, float(np.abs(gz - mu).max()) / s_c))

    def newton(self, pt: _Point, ev: _Eval, g: FloatArray, jty: FloatArray, mu: float,
               delta_last: float) -> tuple[_Newton | None, float, int]:
        """Condense and factor the Newton system (module docstring)."""
        i_xl, i_xu, i_sl, i_su, i_p, i_q = self.slices
        y = pt.y
        sig, mg = pt.z / g, mu / g
        sig_s = sig[i_sl] + sig[i_su]
        r_x = self.obj.grad(pt.x) + jty - mg[i_xl] + mg[i_xu]
        r_s = -y - mg[i_sl] + mg[i_su]
        inv, r_extra = 1.0 / sig_s, r_s / sig_s
        r_p = r_q = pt.p
        if self.ne:
            r_p, r_q = self.rho + y - mg[i_p], self.rho - y - mg[i_q]
            inv = inv + 1.0 / sig[i_p] + 1.0 / sig[i_q]
            r_extra = r_extra - r_p / sig[i_p] + r_q / sig[i_q]
        sig_e = 1.0 / inv
        diag = sig[i_xl] + sig[i_xu] + self.obj.hess(pt.x)
        factor, delta, count = _factor(self.rows.condensed(ev, y, sig_e, diag), delta_last)
        if factor is None:
            return None, delta, count
        return _Newton(factor, sig, sig_s, sig_e, r_x, r_s, r_p, r_q, r_extra), delta, count

    def direction(self, nt: _Newton, ev: _Eval, r_c: FloatArray) -> _Point:
        """Step for the row residual ``r_c`` as a ``_Point`` (``z`` holds the gaps' step)."""
        from scipy.linalg.lapack import dpbtrs

        rows = self.rows
        r_t = r_c + nt.r_extra
        dx, _ = dpbtrs(nt.factor, -nt.r_x - rows.jac_t(ev, nt.sig_e * r_t), lower=1)
        dy = nt.sig_e * (rows.jac(ev, dx) + r_t)
        ds = (dy - nt.r_s) / nt.sig_s
        if not self.ne:
            return _Point(dx, ds, nt.r_p, nt.r_q, dy, np.concatenate((dx, -dx, ds, -ds)))
        dp = (-dy - nt.r_p) / nt.sig[self.slices[4]]
        dq = (dy - nt.r_q) / nt.sig[self.slices[5]]
        return _Point(dx, ds, dp, dq, dy, np.concatenate((dx, -dx, ds, -ds, dp, dq)))

    def dual_step(self, pt: _Point, g: FloatArray, nt: _Newton, d: _Point, mu: float,
                  tau: float) -> tuple[FloatArray, float, float]:
        """The bound multipliers' step, its largest step length and the barrier's slope."""
        mg = mu / g
        dz = mg - pt.z - nt.sig * d.z
        a_dual = _max_step(pt.z, dz, tau)
        dphi = _dot(self.obj.grad(pt.x), d.x) - _dot(mg, d.z)
        if self.ne:
            dphi += self.rho * float(d.p.sum() + d.q.sum())
        return dz, a_dual, dphi

    @staticmethod
    def new_z(z: FloatArray, a_dual: float, dz: FloatArray, g: FloatArray,
              mu: float) -> FloatArray:
        """IPOPT's safeguard: keep each bound multiplier within a factor of mu / gap."""
        return np.minimum(np.maximum(z + a_dual * dz, mu / (KAPPA_SIGMA * g)),
                          KAPPA_SIGMA * mu / g)

    @staticmethod
    def max_step(v: FloatArray, dv: FloatArray, tau: float) -> float:
        return _max_step(v, dv, tau)

    @staticmethod
    def tiny(dv: FloatArray, g: FloatArray) -> float:
        """``max |dv| / (1 + g)`` (IPOPT's tiny-step test)."""
        return float(np.max(np.abs(dv) / (1.0 + g)))

    def trial(self, pt: _Point, d: _Point, alpha: float) -> _Trial:
        """The primal point ``pt + α d`` (multipliers unchanged), evaluated."""
        x = pt.x + alpha * d.x
        p, q = (pt.p + alpha * d.p, pt.q + alpha * d.q) if self.ne else (pt.p, pt.q)
        tp = _Point(x, pt.s + alpha * d.s, p, q, pt.y, pt.z)
        ev = self.rows.evaluate(x)
        return _Trial(tp, ev, self.residual(ev, tp))

    def verdict(self, tr: _Trial, alpha: float, ref: _Reference) -> bool | None:
        """Filter test: True (accept, f-type), False (accept, h-type), None (reject)."""
        theta_t = float(np.abs(tr.residual).sum())
        phi_t = self.barrier(tr.point, self.gaps(tr.point), ref.mu)
        if not np.isfinite(phi_t) or theta_t > ref.theta_max:
            return None
        if any(theta_t >= ft and phi_t >= fp for ft, fp in ref.filt):
            return None
        f_type = ref.dphi < 0 and alpha * (-ref.dphi) ** S_PHI > DELTA * ref.theta**S_THETA
        if ref.theta <= ref.theta_min and f_type:
            return True if phi_t <= ref.phi + ETA_PHI * alpha * ref.dphi else None
        if (theta_t <= (1 - GAMMA_THETA) * ref.theta
                or phi_t <= ref.phi - GAMMA_PHI * ref.theta):
            return False
        return None

    def line_search(
        self, pt: _Point, g: FloatArray, rp: FloatArray, nt: _Newton, ev: _Eval, d: _Point,
        tau: float, ref: _Reference,
    ) -> tuple[bool | None, _Trial, _Point, float]:
        """IPOPT's filter line search with second-order corrections.

        Returns ``(verdict, trial, step, α)``; a ``None`` verdict means no step was accepted.
        """
        theta, dphi = ref.theta, ref.dphi
        alpha = self.max_step(g, d.z, tau)
        if self.tiny(d.z, g) < 10 * np.finfo(float).eps:
            return False, self.trial(pt, d, 1.0), d, 1.0  # tiny step: take it (tiny_step_tol)
        # IPOPT's smallest step before restoration (its eq. 23).
        alpha_min = GAMMA_THETA
        if dphi < 0:
            alpha_min = min(alpha_min, GAMMA_PHI * theta / -dphi)
            if theta <= ref.theta_min:
                alpha_min = min(alpha_min, DELTA * theta**S_THETA / (-dphi) ** S_PHI)
        alpha_min *= ALPHA_MIN_FRAC
        first = True
        tr = self.trial(pt, d, alpha)
        while alpha >= alpha_min:
            tr = self.trial(pt, d, alpha)
            accepted = self.verdict(tr, alpha, ref)
            if accepted is not None:
                return accepted, tr, d, alpha
            if first and float(np.abs(tr.residual).sum()) >= theta:
                # Second-order correction: aim the step at the rows' curvature.
                c_soc, theta_old = alpha * rp + tr.residual, theta
                for _ in range(MAX_SOC):
                    soc = self.direction(nt, ev, c_soc)
                    a_soc = self.max_step(g, soc.z, tau)
                    ts = self.trial(pt, soc, a_soc)
                    accepted = self.verdict(ts, alpha, ref)
                    if accepted is not None:
                        return accepted, ts, soc, a_soc
                    theta_soc = float(np.abs(ts.residual).sum())
                    if theta_soc > KAPPA_SOC * theta_old:
                        break
                    theta_old, c_soc = theta_soc, a_soc * c_soc + ts.residual
            first = False
            alpha *= 0.5
        return None, tr, d, alpha

    def run(self, pt: _Point, mu: float, filt: list[tuple[float, float]],
            max_iter: int) -> _Outcome:
        """Iterate from ``pt`` until converged, stopped, failed or out of iterations."""
        ev = self.rows.evaluate(pt.x)
        g = self.gaps(pt)
        rp = self.residual(ev, pt)
        theta0 = float(np.abs(rp).sum())
        theta_max, theta_min = 1e4 * max(1.0, theta0), 1e-4 * max(1.0, theta0)
        delta_last = 0.0
        n_fact = it = 0
        status = "MaxIterations"
        best_e, best = np.inf, pt
        creeping = 0
        for it in range(max_iter + 1):
            jty = self.rows.jac_t(ev, pt.y)
            e0, e_mu = self.errors(pt, ev, g, jty, mu)
            if e0 <= TOL:
                status = "Solved"
                break
            if e0 < best_e:
                best_e, best = e0, pt
            if it == max_iter:
                break
            if e_mu <= KAPPA_EPS * mu and mu > TOL / 10:  # monotone barrier update
                mu = max(TOL / 10, min(KAPPA_MU * mu, mu**THETA_MU))
                filt = []
            tau = max(TAU_MIN, 1.0 - mu)
            nt, delta, count = self.newton(pt, ev, g, jty, mu, delta_last)
            n_fact += count
            if nt is None:
                status = "InertiaCorrectionFailed"
                break
            if delta > 0:
                delta_last = delta
            d = self.direction(nt, ev, rp)
            dz, a_dual, dphi = self.dual_step(pt, g, nt, d, mu, tau)
            theta = float(np.abs(rp).sum())
            phi = self.barrier(pt, g, mu)
            ref = _Reference(theta, phi, dphi, mu, theta_min, theta_max, filt)
            accepted, tr, step, alpha = self.line_search(pt, g, rp, nt, ev, d, tau, ref)
            if accepted is None:
                if best_e <= ACCEPTABLE_TOL:  # stalled by round-off, near enough
                    return _Outcome("Acceptable", best, mu, filt, it, n_fact)
                filt.append((theta, phi))  # IPOPT adds the current point before restoring
                status = "LineSearchFailed"
                break
            if not accepted:
                filt.append(((1 - GAMMA_THETA) * theta, phi - GAMMA_PHI * theta))
            creeping = creeping + 1 if alpha < STALL_STEP else 0
            if creeping >= STALL_ITERATIONS and best_e <= ACCEPTABLE_TOL and not self.ne:
                return _Outcome("Acceptable", best, mu, filt, it, n_fact)
            ev, rp = tr.ev, tr.residual
            g = self.gaps(tr.point)
            pt = tr.point._replace(y=pt.y + alpha * step.y, z=self.new_z(pt.z, a_dual, dz, g, mu))
            if self.stop is not None:
                stop = self.stop(ev, pt)
                if stop is not None:
                    status = stop
                    break
        if status == "MaxIterations" and best_e <= ACCEPTABLE_TOL:
            return _Outcome("Acceptable", best, mu, filt, it, n_fact)
        return _Outcome(status, pt, mu, filt, it, n_fact)


class _FastEval(NamedTuple):
    """Row values and, per flattened family row, ``D (R_f, 3)``, ``c · w`` and ``sqrt(w)``."""

    c: FloatArray
    d: FloatArray
    load: FloatArray
    sq: FloatArray


class _FastRows:
    """`_Rows` (scaled as it is) with the family rows flattened for the kernels."""

    def __init__(self, rows: _Rows, kernels: ModuleType) -> None:
        self.rows, self.kn = rows, kernels
        self.n, self.size, self.lo, self.hi = rows.n, rows.size, rows.lo, rows.hi
        fams = rows.fams
        self.kk = np.ascontiguousarray(np.concatenate([fa.k for fa in fams]), dtype=np.int64) \
            if fams else np.zeros(0, dtype=np.int64)
        self.cc = np.ascontiguousarray(np.concatenate([fa.c for fa in fams]), dtype=np.float64) \
            if fams else np.zeros((0, 3))
        self.rr = np.ascontiguousarray(np.concatenate([fa.r for fa in fams]), dtype=np.float64) \
            if fams else np.zeros(0)

    def full(self, x: FloatArray) -> FloatArray:
        return self.rows.full(x)

    def evaluate(self, x: FloatArray) -> _FastEval:
        nf = self.kk.size
        ev = _FastEval(np.empty(self.size), np.empty((nf, 3)), np.empty(nf), np.empty(nf))
        self.kn.evaluate(self.rows.w_start, self.rows.w_end, x, self.kk, self.cc, self.rr, *ev)
        return ev

    def jac_t(self, ev: _FastEval, v: FloatArray) -> FloatArray:
        out = np.empty(self.n - 2)
        self.kn.jac_t(v, self.kk, ev.d, out)
        return out


class _FastPhase(_Phase):
    """`_Phase` with each step's array work done by the compiled kernels.

    Same method, same formulas (the kernels' module docstring); only the rounding of sums
    differs. ``objective`` is given as the kernels' ``(mode, a, b)``.
    """

    def __init__(
        self, rows: _FastRows, lb: FloatArray, ub: FloatArray, objective: _Objective,
        mode: tuple[int, FloatArray, FloatArray], *, elastic: bool, rho: float = 0.0,
        stop: Callable[[_Eval, _Point], str | None] | None = None,
    ) -> None:
        super().__init__(rows, lb, ub, objective, elastic=elastic, rho=rho,  # type: ignore[arg-type]
                         stop=stop)
        self.fr, self.kn = rows, rows.kn
        self.mode = mode
        self._gh: tuple[FloatArray, FloatArray, FloatArray] | None = None
        self._gaps: tuple[FloatArray, ...] | None = None
        self._barrier: tuple[Any, ...] | None = None

    def _grad_hess(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Gradient and Hessian of the objective at ``x`` (kept for the same ``x``)."""
        if self._gh is None or self._gh[0] is not x:
            grad, hess = np.empty(x.size), np.empty(x.size)
            self.kn.objective(*self.mode, x, grad, hess)
            self._gh = (x, grad, hess)
        return self._gh[1], self._gh[2]

    def gaps(self, pt: _Point) -> FloatArray:
        # The line search and the accepted step ask for the gaps of the same point.
        c = self._gaps
        if c is not None and c[0] is pt.x and c[1] is pt.s and c[2] is pt.p and c[3] is pt.q:
            return c[4]
        g = np.empty(2 * self.m + 2 * self.rows.size + 2 * self.ne)
        self.kn.gaps(pt.x, pt.s, pt.p, pt.q, self.lb, self.ub, self.fr.lo, self.fr.hi, g)
        self._gaps = (pt.x, pt.s, pt.p, pt.q, g)
        return g

    def residual(self, ev: _Eval | _FastEval, pt: _Point) -> FloatArray:
        out = np.empty(ev.c.size)
        self.kn.residual(ev.c, pt.s, pt.p, pt.q, self.ne, out)
        return out

    def barrier(self, pt: _Point, g: FloatArray, mu: float) -> float:
        # Kept per point: the accepted trial point's barrier is asked again (perhaps at a new
        # mu) as the next iterate's; only mu * Σ log g depends on mu.
        c = self._barrier
        if c is None or c[0] is not pt.x or c[1] is not pt.p or c[2] is not pt.q \
                or c[3] is not g:
            value, logs = self.kn.barrier(*self.mode, pt.x, pt.p, pt.q, self.rho, g)
            c = self._barrier = (pt.x, pt.p, pt.q, g, value, logs)
        return float(c[4] - mu * c[5])

    def errors(self, pt: _Point, ev: _Eval, g: FloatArray, jty: FloatArray,
               mu: float) -> tuple[float, float]:
        grad, _ = self._grad_hess(pt.x)
        res = self.residual(ev, pt)
        e0, e_mu = self.kn.errors(self.m, self.ne, grad, jty, pt.y, pt.z, g, res, res,
                                  self.rho, mu)
        return float(e0), float(e_mu)

    def newton(self, pt: _Point, ev: _Eval, g: FloatArray, jty: FloatArray, mu: float,
               delta_last: float) -> tuple[_Newton | None, float, int]:
        m, r, e = self.m, self.rows.size, self.ne
        grad, hess = self._grad_hess(pt.x)
        fev: _FastEval = ev  # type: ignore[assignment]
        ab, factor = np.empty((3, m)), np.empty((3, m))
        sig = np.empty(g.size)
        sig_s, sig_e, r_s, r_extra = np.empty(r), np.empty(r), np.empty(r), np.empty(r)
        r_x, r_p, r_q = np.empty(m), np.empty(e), np.empty(e)
        delta, count = self.kn.newton(
            m, e, pt.y, pt.z, g, grad, jty, hess, self.fr.kk, fev.d, self.fr.rr, self.fr.cc,
            fev.load, fev.sq, self.rho, mu, delta_last,
            ab, sig, sig_s, sig_e, r_x, r_s, r_p, r_q, r_extra, factor)
        if delta < 0:
            return None, DELTA_W_MAX, int(count)
        if not e:
            r_p = r_q = pt.p
        return _Newton(factor, sig, sig_s, sig_e, r_x, r_s, r_p, r_q, r_extra), delta, int(count)

    def direction(self, nt: _Newton, ev: _Eval, r_c: FloatArray) -> _Point:
        m, r, e = self.m, self.rows.size, self.ne
        fev: _FastEval = ev  # type: ignore[assignment]
        dx, ds, dy = np.empty(m), np.empty(r), np.empty(r)
        dp, dq = (np.empty(e), np.empty(e)) if e else (nt.r_p, nt.r_q)
        dz = np.empty(2 * m + 2 * r + 2 * e)
        self.kn.direction(e, nt.factor, nt.sig, nt.sig_s, nt.sig_e, nt.r_x, nt.r_s, nt.r_p,
                          nt.r_q, nt.r_extra, self.fr.kk, fev.d, r_c, dx, ds, dp, dq, dy, dz)
        return _Point(dx, ds, dp, dq, dy, dz)

    def dual_step(self, pt: _Point, g: FloatArray, nt: _Newton, d: _Point, mu: float,
                  tau: float) -> tuple[FloatArray, float, float]:
        grad, _ = self._grad_hess(pt.x)
        dz = np.empty(g.size)
        a_dual, dphi = self.kn.dual_step(self.ne, grad, d.x, pt.z, g, nt.sig, d.z, mu, tau,
                                         self.rho, dz)
        return dz, float(a_dual), float(dphi)

    def new_z(self, z: FloatArray, a_dual: float,  # type: ignore[override]
              dz: FloatArray, g: FloatArray, mu: float) -> FloatArray:
        out = np.empty(z.size)
        self.kn.new_z(z, a_dual, dz, g, mu, KAPPA_SIGMA, out)
        return out

    def max_step(self, v: FloatArray, dv: FloatArray, tau: float) -> float:  # type: ignore[override]
        return float(self.kn.max_step(v, dv, tau))

    def tiny(self, dv: FloatArray, g: FloatArray) -> float:  # type: ignore[override]
        return float(self.kn.tiny(dv, g))


def _bounds(p: DiscreteProblem) -> tuple[FloatArray, FloatArray]:
    """Bounds on interior ``w``: ``[max(w_min, W_FLOOR), w_max]``, fixed nodes opened.

    The floor is at most `FLOOR_SHARE` of a node's own bound, and a fixed node is opened in
    proportion to its bound: both stay relative at nodes whose bound is tiny (next to a rest).
    """
    ub = p.w_max[1:-1].astype(np.float64)
    lb = np.minimum(W_FLOOR * max(1.0, float(np.max(p.w_max))), FLOOR_SHARE * ub)
    if p.w_min is not None:
        lb = np.maximum(lb, p.w_min[1:-1])
    width = FIXED_WIDTH * np.maximum(ub, np.finfo(float).tiny)
    fixed = ub - lb <= width
    return np.where(fixed, np.maximum(lb - width, 0.5 * lb), lb), np.where(fixed, ub + width, ub)


def _elastic_split(r: FloatArray, a: float) -> tuple[FloatArray, FloatArray]:
    """``p, q > 0`` with ``q - p = r`` and ``p q = a²``."""
    root = np.sqrt(r * r + 4.0 * a * a)
    return 0.5 * (root - r), 0.5 * (root + r)


# --- the compiled kernels: load from numba's cache, or compile in the background ------------


#: The compiled kernels' family (`speedplan.core.jit` loads, compiles or starts it).
KERNELS = FAMILIES["refinement"]


def compile_nlp_kernels() -> None:
    """Make the compiled kernels available in this process now: load them, or compile them.

    `solve_banded_nlp` uses its numpy path until they are (`nlp_kernels_ready`).

    Examples
    --------
    >>> compile_nlp_kernels()
    >>> nlp_kernels_ready()
    True
    """
    KERNELS.compile()


def nlp_kernels_ready(*, start: bool = True) -> bool:
    """Whether the kernels run now without compiling; else compile them in the background.

    They load from numba's cache when they are there. When they are not (first use after
    installation) and ``start`` is true, a background Python process compiles them into the
    cache (as for the relaxation's kernel, and unless ``SPEEDPLAN_BACKGROUND_COMPILE=0``);
    later calls load them once it is done.

    Parameters
    ----------
    start : bool
        Start the background compilation if the kernels are not cached.

    Returns
    -------
    bool
        Whether `solve_banded_nlp` uses the compiled kernels now.

    Examples
    --------
    >>> compile_nlp_kernels()
    >>> nlp_kernels_ready(start=False)
    True
    """
    return KERNELS.ready(start=start)


def _kernels() -> ModuleType | None:
    """The kernels module if it is available now (see `nlp_kernels_ready`).

    Without background compilation (``SPEEDPLAN_BACKGROUND_COMPILE=0``, or no process could
    be started) they are compiled here, as the relaxation's kernel is.
    """
    return KERNELS.available(wait=False)


def solve_banded_nlp(
    problem: DiscreteProblem, w0: FloatArray, start: Start = STARTS[0], *,
    max_iter: int = MAX_ITER, compiled: bool | None = None,
) -> BandedNlpResult:
    """Run the banded interior-point method from ``w0`` (interior nodes free, ends fixed).

    Parameters
    ----------
    problem : DiscreteProblem
        The problem, best in units where ``max(w_max) = 1`` and the mean step is 1 (as
        `speedplan.solve.solve_problem` passes it).
    w0 : ndarray, shape (n,)
        Start (the relaxed ``w``); clipped into the bounds.
    start : Start
        One of `STARTS`.
    max_iter : int
        Iteration limit, restoration included.
    compiled : bool, optional
        Do each iteration's array work in the compiled kernels
        (`speedplan.solve._banded_nlp_kernels`, compiling them here if needed) or in
        numpy; by default the kernels when they are available without compiling (see
        `nlp_kernels_ready`), numpy otherwise. Same method either way.

    Returns
    -------
    BandedNlpResult
        ``success`` when IPOPT's scaled optimality error fell below ``TOL``, or below
        ``ACCEPTABLE_TOL`` where round-off stalled the run.

    Examples
    --------
    A rest-to-rest move whose relaxation violates jerk rows (``J`` varies strongly), in
    units where ``max(w_max) = 1``:

    >>> import numpy as np
    >>> from speedplan.solve import DiscreteProblem
    >>> from speedplan.solve.banded_nlp import solve_banded_nlp
    >>> from speedplan.solve.clarabel_ import solve_relaxation
    >>> from speedplan.solve.paper import paper_instance
    >>> inst = paper_instance("rnd", "cnst", "logrnd", n=200, seed=0)
    >>> scale = inst.w_max.max()
    >>> p = DiscreteProblem(s=np.arange(200.0), w_max=inst.w_max / scale, accel=inst.A / scale,
    ...                     decel=inst.A / scale, jerk=inst.J / scale**1.5)
    >>> relaxed = solve_relaxation(p).w
    >>> bool(p.jerk_violation(relaxed) > p.jerk_tol)
    True
    >>> res = solve_banded_nlp(p, relaxed)
    >>> res.success, bool(p.jerk_violation(res.w) <= p.jerk_tol)
    (True, True)
    >>> bool(p.travel_time(res.w) >= solve_relaxation(p).dual_objective)
    True
    """
    rows = _Rows(problem)
    lb, ub = _bounds(problem)
    x = _push_inside(np.asarray(w0, dtype=np.float64)[1:-1], lb, ub, start.push)
    tau = problem.tau.astype(np.float64)
    if start.gradient_scaling:
        if start.scale_objective:
            grad = _travel_time(tau).grad(x)
            tau = tau * min(1.0, SCALING_MAX_GRADIENT / float(np.abs(grad).max()))
        rows.scale(rows.evaluate(x), SCALING_MAX_GRADIENT)
    kn = _kernels() if compiled is None else (KERNELS.compile() if compiled else None)
    prows: _Rows | _FastRows = rows if kn is None else _FastRows(rows, kn)

    def phase(objective: _Objective, mode: tuple[int, FloatArray, FloatArray],
              **kw: object) -> _Phase:
        if kn is None:
            return _Phase(rows, lb, ub, objective, **kw)  # type: ignore[arg-type]
        return _FastPhase(prows, lb, ub, objective, mode, **kw)  # type: ignore[arg-type]

    main = phase(_travel_time(tau), (0, tau, tau), elastic=False)
    s = _push_inside(rows.evaluate(x).c, rows.lo, rows.hi, start.push)
    empty = np.zeros(0)
    mu = start.mu_init
    pt = _Point(x, s, empty, empty, np.zeros(rows.size), empty)
    pt = pt._replace(z=mu / main.gaps(pt))
    filt: list[tuple[float, float]] = []
    iterations = factorizations = restorations = 0
    while True:
        out = main.run(pt, mu, filt, max_iter - iterations)
        iterations += out.iterations
        factorizations += out.factorizations
        pt, mu, status, filt = out.point, out.mu, out.status, out.filt
        if status != "LineSearchFailed":
            break
        if restorations == MAX_RESTORATIONS or iterations >= max_iter:
            status = "RestorationFailed"
            break
        # Feasibility restoration (IPOPT, Section 3.3): reduce the row violation close to the
        # current point until the original filter accepts the point.
        restorations += 1
        r0 = main.residual(prows.evaluate(pt.x), pt)
        theta_r = float(np.abs(r0).sum())
        mu_r = max(mu, float(np.abs(r0).max()))
        pr, qr = _elastic_split(r0, mu_r / RESTO_RHO)

        def leave(ev: _Eval, tp: _Point, theta_r: float = theta_r, mu: float = mu,
                  filt: list[tuple[float, float]] = filt) -> str | None:
            tp = tp._replace(p=empty, q=empty)
            theta_t = float(np.abs(main.residual(ev, tp)).sum())
            if theta_t > KAPPA_RESTO * theta_r:
                return None
            phi_t = main.barrier(tp, main.gaps(tp), mu)
            if any(theta_t >= ft and phi_t >= fp for ft, fp in filt):
                return None
            return "Restored"

        zeta = np.sqrt(mu)
        resto = phase(_proximity(pt.x, zeta), (1, _proximity_weights(pt.x, zeta), pt.x),
                      elastic=True, rho=RESTO_RHO, stop=leave)
        rpt = _Point(pt.x, pt.s, pr, qr, np.zeros(rows.size), empty)
        rout = resto.run(rpt._replace(z=mu_r / resto.gaps(rpt)), mu_r, [], max_iter - iterations)
        iterations += rout.iterations
        factorizations += rout.factorizations
        if rout.status != "Restored":
            status = "LocallyInfeasible" if rout.status in ("Solved", "Acceptable") \
                else "RestorationFailed"
            break
        # Rows still violated leave their slacks on a bound, where the next step could only
        # move a sliver (fraction to the boundary): push them back inside, as at the start.
        s_back = _push_inside(rout.point.s, rows.lo, rows.hi, start.push)
        pt = _Point(rout.point.x, s_back, empty, empty, np.zeros(rows.size), empty)
        pt = pt._replace(z=mu / main.gaps(pt))
    return BandedNlpResult(
        w=rows.full(pt.x), status=status, success=status in ("Solved", "Acceptable"),
        iterations=iterations, factorizations=factorizations, restorations=restorations,
    )

"""Compiled iteration of the banded interior-point method (see `speedplan.solve.banded`).

Everything here runs under `numba.njit`. One interior-point iteration at ``n = 1000``
is a few hundred small vector operations, which as separate numpy calls cost more than the
arithmetic itself; written as loops over nodes they compile to a few passes over memory.
Every array is allocated once per solve, by the Python driver, with `empty`
(``empty(Point, lay)``, ``empty(Factor, lay)``, ...; ``Scaling.identity(lay)``), whose shapes
`check_sizes` verifies before the kernel runs: with bounds checks off, a wrongly sized
array would be silent memory corruption. Compiled code is cached on disk (``cache=True``), so
only the first use after installation pays the compilation. Arithmetic follows numpy's error model
(division by zero gives ``inf``/``nan``, which the iteration detects and reports as a
numerical breakdown) rather than raising inside compiled code.

How the kernels are compiled shapes them (`speedplan.core.jit`): every kernel that loops over
the nodes is compiled once, for the one signature `signatures` gives it; the kernels that
only call others in sequence (`newton_into`, `start_into`, `step`, ...) are inlined into
`iterate` by numba, since compiled on their own each would be a copy of everything it calls;
`iterate` calls `newton_into` from one place, for the predictor and then the corrector.

Notation follows CVXOPT's ``coneqp``: ``G x + s = b``, ``s ∈ K``, ``G' y + c = 0``, ``y ∈ K``
with ``x = (w, t, z)`` over the ``m`` interior nodes. ``K`` is a product of nonnegative
orthants (the linear rows) and ``2 m`` three-dimensional second-order cones, stored
column-wise in arrays of shape ``(3, 2 m)``: first the node cones ``z² <= w``, then the
cones ``t z >= 1``. The linear rows are ordered in blocks whose offsets `Layout`
holds: acceleration (``m + 1``), braking (``m + 1``), upper bounds (``m``), lower bounds
(``kl``, nodes ``lk``), positive jerk rows (``k``, by node: ``jstart``), negative jerk rows
(``k``). Functions named ``*_into`` write their result into the trailing array arguments.
The reduced Newton system is derived in ``docs/banded-ipm.md``.
"""

from __future__ import annotations

import inspect
import math
from typing import Any, NamedTuple, TypeVar

import numpy as np
from numba import njit

from ..core.checks import FloatArray, IntArray
from ..core.jit import inlined, inner, kernel, tolerate_stale_indexes

tolerate_stale_indexes()  # before any kernel below is loaded from the cache

_T = TypeVar("_T")

#: Fraction of the step to the cone boundary taken per iteration, by the primal and the dual
#: variables each (their steps are taken apart, see `step`).
STEP = 0.99
#: Exponent of Mehrotra's centring heuristic ``σ = (1 - α_affine)^3``.
SIGMA_EXPONENT = 3.0
#: The corrector's second-order term ``(W⁻¹Δs_a) ∘ (WΔy_a)`` is weighted by
#: ``α_affine ** SECOND_ORDER_EXPONENT``. Mehrotra's full term predicts the complementarity
#: after a full affine step; where only a short one is possible it is far larger than what
#: any step realises, and it blocks the next step: on fine grids along a curved speed bound
#: the full term makes the method advance one node per iteration, with steps of 0.01-0.08,
#: and stop with NoProgress (a right-angle corner at a yaw-rate limit on uniform grids of
#: 2-3.3 mm). Salahi, Peng and Terlaky's modified corrector weights the term by the affine
#: step itself; its square root does as well as any exponent tried (0.25-2), and with the
#: separate primal and dual steps of `step` it solves those grids and takes a median 20 %
#: fewer iterations on 7 000-18 000-node comfort grids (docs/banded-ipm.md).
SECOND_ORDER_EXPONENT = 0.5
#: Relative gap below which each Newton solve is checked for iterative refinement.
REFINE_BELOW = 1e-3
#: The check refines when the solve's residual in ``G'Δy = bx``, relative like the dual
#: residual, exceeds this fraction of ``tol``: there it can matter for convergence (fine grids,
#: strongly varying ``J``); on most instances it is far smaller and a round would be wasted.
REFINE_RESIDUAL = 0.01
#: Iterations without halving the relative gap after which the method is declared stalled.
STALL_ITERATIONS = 5
#: Relative gap below which a stalled method reports STALLED; also the certified relative gap
#: with which `banded` accepts any stop short of ``tol`` ("AlmostSolved").
ALMOST_GAP = 1e-6
#: Iterations without halving the relative gap or either relative residual after which the
#: method gives up at any gap (seen on a few long, strongly graded grids, where it jams near a
#: gap of 1e-2; the caller then falls back to Clarabel rather than spending ``max_iter``
#: iterations). The residuals count: next to a slow zone or a hairpin the gap can take 20
#: iterations to halve while both residuals fall 30-fold, and the method then converges
#: (fuzz_zones seed 2 case 98: stopped at iteration 56 by the gap alone, solved at 117).
NO_PROGRESS_ITERATIONS = 20

#: How `g_adjoint_into` writes ``G' y`` into its output.
ADJ_SET, ADJ_SUBTRACT, ADJ_ADD, ADJ_DUAL_RESIDUAL = 0, 1, 2, 3

#: Columns of `iterate`'s log, one row per iteration.
LOG_COLUMNS = ("pcost", "dcost", "relgap", "pres", "dres", "sigma", "primal_step",
               "dual_step")

#: Status codes returned by `iterate`.
SOLVED, MAX_ITERATIONS, STALLED, NUMERICAL_ERROR, NO_PROGRESS = 0, 1, 2, 3, 4
STATUS_NAMES = ("Solved", "MaxIterations", "Stalled", "NumericalError", "NoProgress")


# --- layout and storage ---------------------------------------------------------------------


class Layout(NamedTuple):
    """Sizes and row-block offsets of one problem, computed once by `layout`."""

    m: int  # interior nodes
    k: int  # stencil (jerk-type) rows of each sign, all families
    kl: int  # lower-bound rows
    dec: int  # first braking row (the acceleration rows start at 0)
    up: int  # first upper-bound row
    low: int  # first lower-bound row
    jp: int  # first positive jerk row
    jm: int  # first negative jerk row
    n_lin: int  # linear rows in all
    nc: int  # second-order cones (2 m)


def layout(m: int, k: int, kl: int) -> Layout:
    """Offsets of the linear row blocks for ``m`` interior nodes, ``k`` jerk and ``kl`` floors."""
    nl = m + 1
    up = 2 * nl
    low = up + m
    jp = low + kl
    jm = jp + k
    return Layout(m=m, k=k, kl=kl, dec=nl, up=up, low=low, jp=jp, jm=jm, n_lin=jm + k,
                  nc=2 * m)


def _shape(kind: str, lay: Layout) -> tuple[int, ...]:
    """Shape of an array of ``kind``.

    Per node, linear row, right-hand side (linear rows before the negative jerk rows), cone
    (3, nc), cone, jerk row, stencil (3, k), node starts (m + 1), floor.
    """
    return {"node": (lay.m,), "lin": (lay.n_lin,), "rhs": (lay.jm,), "cone": (3, lay.nc),
            "cones": (lay.nc,),
            "jerk": (lay.k,), "stencil": (3, lay.k), "start": (lay.m + 1,),
            "low": (lay.kl,)}[kind]


def empty(cls: type[_T], lay: Layout) -> _T:
    """Zero-filled arrays of the shapes ``lay`` asks for, one per field of ``cls``."""
    kinds = _KINDS[cls]
    return cls(*(np.zeros(_shape(kinds[f], lay)) for f in cls._fields))  # type: ignore[attr-defined]


def _check(obj: tuple[Any, ...], lay: Layout) -> None:
    """Raise `ValueError` unless every array of ``obj`` has its shape for ``lay``."""
    kinds = _KINDS[type(obj)]
    for name, arr in zip(obj._fields, obj, strict=True):  # type: ignore[attr-defined]
        if name not in kinds:
            continue
        want = _shape(kinds[name], lay)
        dtype = np.intp if name in ("lk", "jstart") else np.float64
        if not (isinstance(arr, np.ndarray) and arr.shape == want and arr.dtype == dtype
                and arr.flags.c_contiguous):
            got = getattr(arr, "shape", type(arr).__name__)
            raise ValueError(f"{type(obj).__name__}.{name}: expected shape {want} of "
                             f"{np.dtype(dtype)}, got {got} {getattr(arr, 'dtype', '')}")


class Data(NamedTuple):
    """Problem data in internal units (see `speedplan.solve.banded._prepare`).

    The stencil rows of every family (jerk, lateral jerk) are listed together, ordered by
    node: the rows of node ``i`` are ``r`` in ``jstart[i]:jstart[i + 1]``, and row ``r`` reads
    ``±cj_r (jc_r · ŵ_{i-1:i+2}) - t̂_i <= b``. Every loop over the rows visits them node by
    node, so no row stores its node.
    """

    jstart: IntArray  # first row of each node, shape (m + 1,)
    jc: FloatArray  # stencil of each row over ŵ_{i-1}, ŵ_i, ŵ_{i+1}, shape (3, k)
    cj: FloatArray  # coefficient of the stencil in its rows
    lk: IntArray  # interior nodes with a positive lower bound
    ct: FloatArray  # objective coefficients of t
    cw: FloatArray  # coefficients of w in the acceleration rows
    b_lin: FloatArray  # right-hand side of the linear rows but the negative jerk rows
    lay: Layout

    def rhs_lin(self) -> FloatArray:
        """The right-hand side of every linear row, shape ``(n_lin,)`` (see `_b_lin`)."""
        lay = self.lay
        return np.concatenate((self.b_lin, -self.b_lin[lay.jp : lay.jm]))

    def check(self) -> None:
        """Raise `ValueError` unless every array has its shape for ``self.lay``."""
        _check(self, self.lay)
        js = self.jstart
        if not (js[0] == 0 and js[-1] == self.lay.k and bool(np.all(np.diff(js) >= 0))):
            raise ValueError("Data.jstart must index the rows of each node: non-decreasing "
                             "from 0 to the number of stencil rows")
        if self.lk.size and not bool(np.all(np.diff(self.lk) > 0)):
            raise ValueError("Data.lk must be strictly increasing (one floor per node)")


class Point(NamedTuple):
    """Primal–dual iterate: ``x = (w, t, z)``, linear slacks ``sl`` and multipliers ``y``.

    The cones' slacks are not stored: they are kept equal to ``b - G x`` (`_cone_s`),
    which the start makes strictly interior, so the cone rows' primal residual is zero
    throughout and their ``Δs = -G Δx`` (`_cone_ds`).
    """

    w: FloatArray
    t: FloatArray
    z: FloatArray
    sl: FloatArray  # linear rows
    yl: FloatArray
    ys: FloatArray  # cones (3, nc)



class Residual(NamedTuple):
    """The dual residual, negated: ``-(G'y + c)``.

    The primal residual of the linear rows is the same number on every row (the start's
    shift, scaled by ``1 - α_primal`` at each step), carried as a scalar ``rp``; the cone rows
    have none (see `Point`).
    """

    gw: FloatArray
    gt: FloatArray
    gz: FloatArray



class Direction(NamedTuple):
    """A Newton direction ``(Δx, Δs, Δy)``; the cones' ``Δs = -G Δx`` is not stored."""

    dw: FloatArray
    dt: FloatArray
    dz: FloatArray
    dsl: FloatArray
    dyl: FloatArray
    dys: FloatArray



class Scaling(NamedTuple):
    """Nesterov–Todd scaling ``W`` of the cones at the current ``(s, y)``.

    The linear rows' scaling ``W = diag(sqrt(s / y))`` is never formed: only ``W² = s / y``
    and ``λ² = s y`` enter the Newton system. The scaled point ``λ = W y = W⁻¹ s`` is
    computed where it is used (`_lambda`).
    """

    beta: FloatArray  # cones: W = β (2 v v' - J)
    v: FloatArray

    @classmethod
    def identity(cls, lay: Layout) -> Scaling:
        """``W = I`` (``β = 1``, ``v = e``): the scaling of the starting point."""
        sc = empty(cls, lay)
        sc.beta[:] = 1.0
        sc.v[0] = 1.0
        return sc


class Factor(NamedTuple):
    """``L D L'`` factor of the reduced matrix and the per-node elimination of ``(t, z)``.

    The linear rows' weights ``H = y / s`` are not stored: each use divides.
    """

    l1: FloatArray  # L[i, i-1]
    l2: FloatArray  # L[i, i-2]
    dd: FloatArray  # D
    alpha: FloatArray  # per stencil row: coupling of t_i to (jc_r · ŵ) in G'HG
    bwz: FloatArray  # coupling of z_i to w_i
    p: FloatArray  # inverse of the (t, z) block: [[p, q], [q, r]]
    q: FloatArray
    r: FloatArray



_KINDS: dict[type, dict[str, str]] = {
    Data: {"jstart": "start", "jc": "stencil", "cj": "jerk", "lk": "low",
           "ct": "node", "cw": "node", "b_lin": "rhs"},
    Point: {"w": "node", "t": "node", "z": "node", "sl": "lin", "yl": "lin", "ys": "cone"},
    Residual: dict.fromkeys(Residual._fields, "node"),
    Direction: {"dw": "node", "dt": "node", "dz": "node", "dsl": "lin", "dyl": "lin",
                "dys": "cone"},
    Scaling: {"beta": "cones", "v": "cone"},
    Factor: {**dict.fromkeys(Factor._fields, "node"), "alpha": "jerk"},
}


def check_sizes(d: Data, *parts: tuple[Any, ...]) -> None:
    """Check the shapes of ``d`` and of every array tuple against ``d.lay``.

    Call `Data.check` (shapes and row order) once before allocating the kernel's
    arrays: its temporaries would otherwise add to the solve's peak memory.
    """
    _check(d, d.lay)
    for part in parts:
        _check(part, d.lay)


# --- per-cone and per-node scalar kernels ------------------------------------------------------


@inner
def _pad(w: FloatArray, i: int) -> float:
    """``w[i]`` with zero outside ``0 <= i < len(w)`` (the eliminated end values)."""
    if i < 0 or i >= w.size:
        return 0.0
    return float(w[i])


@inner
def _b_lin(d: Data, j: int) -> float:
    """Right-hand side of linear row ``j``.

    The negative jerk rows' is that of the positive ones negated (both are the fixed ends'
    share of the same stencil), so ``Data.b_lin`` stops at the first negative jerk row.
    """
    return float(d.b_lin[j]) if j < d.lay.jm else -float(d.b_lin[j - d.lay.k])


@inner
def _stencil_dot(d: Data, w: FloatArray, i: int, r: int) -> float:
    """``jc_r · w_{i-1:i+2}`` for stencil row ``r`` at node ``i`` (zero outside the nodes)."""
    return float(d.jc[0, r] * _pad(w, i - 1) + d.jc[1, r] * w[i] + d.jc[2, r] * _pad(w, i + 1))


@inner
def _scatter_stencil(d: Data, i: int, r: int, value: float, out: FloatArray) -> None:
    """``out += value * jc_r`` at ``w_{i-1:i+2}`` (the adjoint of `_stencil_dot`)."""
    if i > 0:
        out[i - 1] += value * d.jc[0, r]
    out[i] += value * d.jc[1, r]
    if i + 1 < out.size:
        out[i + 1] += value * d.jc[2, r]


@inner
def _jnorm2(u0: float, u1: float, u2: float) -> float:
    """``u' J u`` with ``J = diag(1, -1, -1)``, computed as ``(u_0 - |u_a|)(u_0 + |u_a|) - u_b²``.

    ``a`` is the larger of the two other components. Near the cone boundary the plain
    ``u_0² - u_1² - u_2²`` cancels to the square of the largest entry; pairing ``u_0`` with
    the largest entry first keeps the error relative to the smaller one.
    """
    a1, a2 = abs(u1), abs(u2)
    big, small = (a1, a2) if a1 >= a2 else (a2, a1)
    return (u0 - big) * (u0 + big) - small * small


@inner
def _h_entries(sc: Scaling, c: int) -> tuple[float, float, float, float, float, float]:
    """Entries 00, 01, 02, 11, 12, 22 of cone ``c``'s ``H = W⁻² = (2 ŵ ŵ' - J) / β²``.

    ``ŵ = J wbar`` with the scaling point ``wbar = 2 v_0 v - e``.
    """
    v0, v1, v2 = sc.v[0, c], sc.v[1, c], sc.v[2, c]
    u0, u1, u2 = 2.0 * v0 * v0 - 1.0, -2.0 * v0 * v1, -2.0 * v0 * v2
    ib2 = 1.0 / (sc.beta[c] * sc.beta[c])
    return ((2.0 * u0 * u0 - 1.0) * ib2, 2.0 * u0 * u1 * ib2, 2.0 * u0 * u2 * ib2,
            (2.0 * u1 * u1 + 1.0) * ib2, 2.0 * u1 * u2 * ib2, (2.0 * u2 * u2 + 1.0) * ib2)


@inner
def _apply_h(sc: Scaling, u0: float, u1: float, u2: float, c: int) -> tuple[float, float, float]:
    """``H u`` for cone ``c``."""
    h00, h01, h02, h11, h12, h22 = _h_entries(sc, c)
    return (h00 * u0 + h01 * u1 + h02 * u2, h01 * u0 + h11 * u1 + h12 * u2,
            h02 * u0 + h12 * u1 + h22 * u2)


@inner
def _apply_w(sc: Scaling, u0: float, u1: float, u2: float, c: int) -> tuple[float, float, float]:
    """``W u`` for cone ``c``: ``W = β (2 v v' - J)``."""
    v0, v1, v2, bt = sc.v[0, c], sc.v[1, c], sc.v[2, c], sc.beta[c]
    vu = v0 * u0 + v1 * u1 + v2 * u2
    return bt * (2.0 * vu * v0 - u0), bt * (2.0 * vu * v1 + u1), bt * (2.0 * vu * v2 + u2)


@inner
def _apply_winv(
    sc: Scaling, u0: float, u1: float, u2: float, c: int
) -> tuple[float, float, float]:
    """``W⁻¹ u`` for cone ``c``: ``W⁻¹ = (2 Jv (Jv)' - J) / β``."""
    j0, j1, j2, bt = sc.v[0, c], -sc.v[1, c], -sc.v[2, c], sc.beta[c]
    vu = j0 * u0 + j1 * u1 + j2 * u2
    return (2.0 * vu * j0 - u0) / bt, (2.0 * vu * j1 + u1) / bt, (2.0 * vu * j2 + u2) / bt


@inner
def _jordan_solve(
    l0: float, l1: float, l2: float, b0: float, b1: float, b2: float
) -> tuple[float, float, float]:
    """Solve ``λ ∘ u = b`` for ``u`` (one cone)."""
    u0 = (l0 * b0 - l1 * b1 - l2 * b2) / _jnorm2(l0, l1, l2)
    return u0, (b1 - u0 * l1) / l0, (b2 - u0 * l2) / l0


@inner
def _b_soc(r: int, c: int, m: int) -> float:
    """Constant part of the cone rows: ``(1, 0, -1)`` for node cones, ``(0, 0, 2)`` for t-z."""
    if r == 1:
        return 0.0
    if c < m:
        return 1.0 if r == 0 else -1.0
    return 0.0 if r == 0 else 2.0


@inner
def _cone_s(w: FloatArray, t: FloatArray, z: FloatArray, c: int) -> tuple[float, float, float]:
    """Cone ``c``'s slack ``b - G x``: ``(1 + w, 2 z, w - 1)`` (node) or ``(t + z, t - z, 2)``."""
    m = w.size
    if c < m:
        return 1.0 + w[c], 2.0 * z[c], w[c] - 1.0
    i = c - m
    return t[i] + z[i], t[i] - z[i], 2.0


@inner
def _cone_ds(
    dw: FloatArray, dt: FloatArray, dz: FloatArray, c: int
) -> tuple[float, float, float]:
    """Cone ``c``'s ``Δs = -G Δx``, the change of `_cone_s` along ``Δx``."""
    m = dw.size
    if c < m:
        return dw[c], 2.0 * dz[c], dw[c]
    i = c - m
    return dt[i] + dz[i], dt[i] - dz[i], 0.0


# --- the constraint map G and its adjoint -------------------------------------------------


@inner
def g_lin_into(d: Data, w: FloatArray, t: FloatArray, out: FloatArray) -> None:
    """Linear rows of ``G x`` (no constants)."""
    lay = d.lay
    m = lay.m
    for j in range(lay.dec):
        right = d.cw[j] * w[j] if j < m else 0.0
        left = d.cw[j - 1] * w[j - 1] if j > 0 else 0.0
        out[j] = right - left
        out[lay.dec + j] = left - right
    for i in range(m):
        out[lay.up + i] = w[i]
    for r in range(lay.kl):
        out[lay.low + r] = -w[d.lk[r]]
    for i in range(m):
        for r in range(d.jstart[i], d.jstart[i + 1]):
            jw = d.cj[r] * _stencil_dot(d, w, i, r)
            out[lay.jp + r] = jw - t[i]
            out[lay.jm + r] = -jw - t[i]


@inner
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


@inner
def g_adjoint_into(
    d: Data, yl: FloatArray, ys: FloatArray, gw: FloatArray, gt: FloatArray, gz: FloatArray,
    mode: int,
) -> tuple[float, float, float]:
    """``G' y`` split into its ``w``, ``t`` and ``z`` parts, written into ``g`` by ``mode``.

    ``ADJ_SET`` (and any other value): ``g = G' y``; ``ADJ_SUBTRACT``: ``g -= G' y``;
    ``ADJ_ADD``: ``g += G' y``; ``ADJ_DUAL_RESIDUAL``: ``g = -(G' y + c)`` (``c`` is ``ct``
    on ``t``). The floors ``lk`` must be strictly increasing (`Data.check`). Each entry is
    formed whole, node by node, before it is written: the stencil rows of nodes ``i - 1``,
    ``i`` and ``i + 1`` are gathered in row order, so the modes round as the finished
    ``G' y`` combined with ``g``, one pass over memory where a separate pass would add a
    second. Returns the squared norms of the three parts as written.
    """
    lay = d.lay
    m = lay.m
    sw = st = sz = 0.0
    rl = 0  # floors, by increasing node
    for i in range(m):
        acc_i = yl[i] - yl[lay.dec + i]
        acc_n = yl[i + 1] - yl[lay.dec + i + 1]
        vw = (d.cw[i] * (acc_i - acc_n) + yl[lay.up + i]
              - ys[0, i] - ys[2, i])
        vt = -(ys[0, m + i] + ys[1, m + i])
        vz = -2.0 * ys[1, i] - ys[0, m + i] + ys[1, m + i]
        while rl < lay.kl and d.lk[rl] == i:
            vw -= yl[lay.low + rl]
            rl += 1
        for node in range(max(i - 1, 0), min(i + 2, m)):
            for r in range(d.jstart[node], d.jstart[node + 1]):
                jp, jm = yl[lay.jp + r], yl[lay.jm + r]
                vw += d.cj[r] * (jp - jm) * d.jc[i - node + 1, r]
                if node == i:
                    vt -= jp + jm
        if mode == ADJ_SUBTRACT:
            vw, vt, vz = gw[i] - vw, gt[i] - vt, gz[i] - vz
        elif mode == ADJ_ADD:
            vw, vt, vz = vw + gw[i], vt + gt[i], vz + gz[i]
        elif mode == ADJ_DUAL_RESIDUAL:
            vw, vt, vz = -vw, -(vt + d.ct[i]), -vz
        gw[i], gt[i], gz[i] = vw, vt, vz
        sw += vw * vw
        st += vt * vt
        sz += vz * vz
    return sw, st, sz


# --- cones: steps, interiority, scaling --------------------------------------------------------


@inner
def _cone_step(
    u0: float, u1: float, u2: float, du0: float, du1: float, du2: float
) -> float:
    """Largest ``α`` with ``u + α du`` in the cone (``u`` interior); ``inf`` if unbounded."""
    a = _jnorm2(du0, du1, du2)
    b = u0 * du0 - u1 * du1 - u2 * du2
    cc = _jnorm2(u0, u1, u2)
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
    if du0 < 0.0:
        root = min(root, -u0 / du0)
    return root


@inner
def max_step_soc(u: FloatArray, du: FloatArray) -> float:
    """Largest ``α`` with ``u + α du`` in every cone (``u`` interior); ``inf`` if unbounded."""
    best = np.inf
    for c in range(u.shape[1]):
        best = min(best, _cone_step(u[0, c], u[1, c], u[2, c], du[0, c], du[1, c], du[2, c]))
    return best


@inner
def max_step_slack_soc(pt: Point, dn: Direction) -> float:
    """`max_step_soc` for the cones' slacks ``s = b - G x`` along ``Δs = -G Δx``."""
    best = np.inf
    for c in range(pt.ys.shape[1]):
        s0, s1, s2 = _cone_s(pt.w, pt.t, pt.z, c)
        d0, d1, d2 = _cone_ds(dn.dw, dn.dt, dn.dz, c)
        best = min(best, _cone_step(s0, s1, s2, d0, d1, d2))
    return best


@inner
def max_step_lin(u: FloatArray, du: FloatArray) -> float:
    """Largest ``α`` with ``u + α du >= 0`` (``u > 0``); ``inf`` if unbounded."""
    worst = 0.0
    for i in range(u.size):
        worst = max(worst, -du[i] / u[i])
    return 1.0 / worst if worst > 0.0 else np.inf


@inner
def _interior(u0: float, u1: float, u2: float) -> bool:
    """Whether ``u`` is strictly inside the cone."""
    return u0 > 0.0 and _jnorm2(u0, u1, u2) > 0.0


@inner
def _interior_after_step(
    pt: Point, alpha: float, alpha_dual: float, dn: Direction
) -> tuple[bool, bool]:
    """Whether the cones of ``s``, and those of ``y``, are all strictly interior after the steps.

    ``s`` moves by ``α`` (``alpha``), ``y`` by ``alpha_dual``; one answer per side.
    """
    primal = dual = True
    for c in range(pt.ys.shape[1]):
        if primal:
            s0, s1, s2 = _cone_s(pt.w, pt.t, pt.z, c)
            d0, d1, d2 = _cone_ds(dn.dw, dn.dt, dn.dz, c)
            primal = _interior(s0 + alpha * d0, s1 + alpha * d1, s2 + alpha * d2)
        if dual:
            dual = _interior(pt.ys[0, c] + alpha_dual * dn.dys[0, c],
                             pt.ys[1, c] + alpha_dual * dn.dys[1, c],
                             pt.ys[2, c] + alpha_dual * dn.dys[2, c])
        if not (primal or dual):
            break
    return primal, dual


@inner
def cone_scaling_into(
    sc: Scaling, c: int, s0: float, s1: float, s2: float, y0: float, y1: float, y2: float
) -> None:
    """Nesterov–Todd scaling of cone ``c`` at ``(s, y)`` (CVXOPT's ``misc.compute_scaling``)."""
    sn = math.sqrt(_jnorm2(s0, s1, s2))
    yn = math.sqrt(_jnorm2(y0, y1, y2))
    bt = math.sqrt(sn / yn)
    s0, s1, s2 = s0 / sn, s1 / sn, s2 / sn
    y0, y1, y2 = y0 / yn, y1 / yn, y2 / yn
    gamma = math.sqrt(0.5 * (1.0 + s0 * y0 + s1 * y1 + s2 * y2))
    wb0 = (s0 + y0) / (2.0 * gamma)
    wb1 = (s1 - y1) / (2.0 * gamma)
    wb2 = (s2 - y2) / (2.0 * gamma)
    nv = math.sqrt(2.0 * (wb0 + 1.0))
    sc.beta[c] = bt
    sc.v[0, c], sc.v[1, c], sc.v[2, c] = (wb0 + 1.0) / nv, wb1 / nv, wb2 / nv


@inner
def scaling_into(pt: Point, sc: Scaling) -> None:
    """Nesterov–Todd scaling of every cone at the iterate's ``(s, y)``."""
    ys = pt.ys
    for c in range(ys.shape[1]):
        s0, s1, s2 = _cone_s(pt.w, pt.t, pt.z, c)
        cone_scaling_into(sc, c, s0, s1, s2, ys[0, c], ys[1, c], ys[2, c])


@inner
def _lambda(sc: Scaling, ys: FloatArray, c: int) -> tuple[float, float, float]:
    """The scaled point ``λ = W y`` of cone ``c`` (equal to ``W⁻¹ s``)."""
    return _apply_w(sc, ys[0, c], ys[1, c], ys[2, c], c)


# --- the reduced (pentadiagonal) Newton system --------------------------------------------


@inner
def _eliminate_tz(
    d: Data, sc: Scaling, yl: FloatArray, sl: FloatArray, fac: Factor, i: int
) -> tuple[float, float, float, float, float, float, float]:
    """Eliminate ``(t_i, z_i)`` from node ``i``'s rows of ``G' H G``; returns ``M_i`` and more.

    Writes the inverse ``[[p, q], [q, r]]`` of the ``(t_i, z_i)`` block, the coupling
    ``b_wz`` of ``z_i`` to ``w_i`` and, per stencil row ``r`` of the node, the coupling
    ``α_r = -c_r (H⁺_r - H⁻_r)`` of ``t_i`` to ``a_r · ŵ`` (``H = y / s``).
    Each stencil row ``±c_r (a_r · ŵ) - t̂_i`` adds ``σ_r c_r² a_r a_r'`` (``σ_r = H⁺_r + H⁻_r``)
    to the ``w`` block and ``σ_r`` to the diagonal of ``t_i``. Returns the six entries
    00, 01, 02, 11, 12, 22 of the block over ``w_{i-1:i+2}`` left by the elimination,
    ``M_i = Σ_rs E_rs a_r a_s' + Σ_r φ_r (a_r e' + e a_r')`` (``e`` the middle unit vector,
    ``E = diag(σ c²) - p α α'``, ``φ_r = -q α_r b_wz``), and the diagonal weight of ``w_i``
    from its own bound and node cone (docs/banded-ipm.md).
    """
    lay = d.lay
    m = lay.m
    h00, h01, h02, h11, h12, h22 = _h_entries(sc, i)
    g00, g01, _, g11, _, _ = _h_entries(sc, m + i)
    mtt = g00 + 2.0 * g01 + g11
    mzz = 4.0 * h11 + g00 - 2.0 * g01 + g11
    mtz = g00 - g11
    bwz = 2.0 * (h01 + h12)
    fac.bwz[i] = bwz
    dg = yl[lay.up + i] / sl[lay.up + i] + (h00 + 2.0 * h02 + h22)
    r0, r1 = d.jstart[i], d.jstart[i + 1]
    hsum = 0.0
    for r in range(r0, r1):
        hp, hm = yl[lay.jp + r] / sl[lay.jp + r], yl[lay.jm + r] / sl[lay.jm + r]
        fac.alpha[r] = -d.cj[r] * (hp - hm)
        hsum += hp + hm
    # κ: the cones' own weight of t once z is eliminated; p = 1 / (κ + Σσ).
    kappa = mtt - mtz * mtz / mzz
    mtt += hsum
    det = mtt * mzz - mtz * mtz
    p, q = mzz / det, -mtz / det
    fac.p[i], fac.q[i], fac.r[i] = p, q, mtt / det
    m00 = m01 = m02 = m11 = m12 = m22 = 0.0
    for r in range(r0, r1):
        hp, hm = yl[lay.jp + r] / sl[lay.jp + r], yl[lay.jm + r] / sl[lay.jm + r]
        sig = hp + hm
        # E_rr = c² σ - p α², written without cancellation as
        # c² (σ (κ + Σσ - σ) + 4 H⁺H⁻) / (κ + Σσ).
        err = d.cj[r] ** 2 * (sig * (kappa + hsum - sig) + 4.0 * hp * hm) / (hsum + kappa)
        a0, a1, a2 = d.jc[0, r], d.jc[1, r], d.jc[2, r]
        phi = -q * fac.alpha[r] * bwz
        m00 += err * a0 * a0
        m01 += err * a0 * a1 + phi * a0
        m02 += err * a0 * a2
        m11 += err * a1 * a1 + 2.0 * phi * a1
        m12 += err * a1 * a2 + phi * a2
        m22 += err * a2 * a2
        for s_ in range(r + 1, r1):  # pairs of rows at one node (several families)
            ers = -p * fac.alpha[r] * fac.alpha[s_]
            b0, b1, b2 = d.jc[0, s_], d.jc[1, s_], d.jc[2, s_]
            m00 += 2.0 * ers * a0 * b0
            m01 += ers * (a0 * b1 + a1 * b0)
            m02 += ers * (a0 * b2 + a2 * b0)
            m11 += 2.0 * ers * a1 * b1
            m12 += ers * (a1 * b2 + a2 * b1)
            m22 += 2.0 * ers * a2 * b2
    return m00, m01, m02, m11, m12, m22, dg


@inner
def factor_into(d: Data, sc: Scaling, yl: FloatArray, sl: FloatArray, fac: Factor) -> bool:
    """Assemble the Schur complement in ``w`` of ``G' H G`` and factor it.

    The linear rows are weighted by ``H = yl / sl`` and the cones by ``H`` of ``sc``.
    Eliminating ``(t_i, z_i)`` node by node leaves a pentadiagonal matrix (every stencil
    spans three nodes), factored as ``L D L'`` with a unit lower triangular ``L`` of
    bandwidth 2, in the same pass: row ``i`` needs the blocks ``M_{i-1}, M_i, M_{i+1}``,
    so node ``i + 1`` is eliminated one step ahead. Returns False if the matrix is not
    numerically positive definite.
    """
    lay = d.lay
    m, dec = lay.m, lay.dec
    l1, l2, dd = fac.l1, fac.l2, fac.dd
    p02 = p12 = p22 = 0.0  # the entries of M_{i-1} that row i needs
    _, c01, c02, c11, c12, c22, cdg = _eliminate_tz(d, sc, yl, sl, fac, 0)
    rl = 0
    while rl < lay.kl and d.lk[rl] == 0:
        cdg += yl[lay.low + rl] / sl[lay.low + rl]
        rl += 1
    ok = True
    gacc_n = yl[0] / sl[0] + yl[dec] / sl[dec]  # weights of the acceleration rows of node i
    for i in range(m):
        n00 = n01 = n02 = n11 = n12 = n22 = ndg = 0.0
        if i + 1 < m:
            n00, n01, n02, n11, n12, n22, ndg = _eliminate_tz(d, sc, yl, sl, fac, i + 1)
            while rl < lay.kl and d.lk[rl] == i + 1:
                ndg += yl[lay.low + rl] / sl[lay.low + rl]
                rl += 1
        gacc_i = gacc_n
        gacc_n = yl[i + 1] / sl[i + 1] + yl[dec + i + 1] / sl[dec + i + 1]
        # S[i, i] gathers M_i's middle, M_{i+1}'s first and M_{i-1}'s last entry.
        di = c11 + cdg - fac.r[i] * fac.bwz[i] ** 2 + d.cw[i] ** 2 * (gacc_i + gacc_n)
        off1 = 0.0
        if i + 1 < m:
            di += n00
        if i > 0:
            di += p22
            off1 = c01 + p12 - d.cw[i - 1] * d.cw[i] * gacc_i
        if i > 1:
            l2[i] = p02 / dd[i - 2]
            di -= l2[i] * l2[i] * dd[i - 2]
        else:
            l2[i] = 0.0
        if i > 0:
            b = off1
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
        p02, p12, p22 = c02, c12, c22
        c01, c02, c11, c12, c22, cdg = n01, n02, n11, n12, n22, ndg
    return ok


@inner
def solve_banded_inplace(fac: Factor, x: FloatArray) -> None:
    """Overwrite ``x`` with ``(L D L')⁻¹ x``."""
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


@inner
def solve_normal_inplace(
    d: Data, fac: Factor, xw: FloatArray, xt: FloatArray, xz: FloatArray
) -> None:
    """Overwrite ``(xw, xt, xz)`` with the solution of ``G' H G Δx = (xw, xt, xz)``.

    ``(t, z)`` are eliminated node by node, the pentadiagonal system in ``w`` is solved,
    and ``(t, z)`` are recovered.
    """
    m = xw.size
    for i in range(m):
        rt, rz = xt[i], xz[i]
        xt[i] = fac.p[i] * rt + fac.q[i] * rz
        xz[i] = fac.q[i] * rt + fac.r[i] * rz
        xw[i] -= fac.bwz[i] * xz[i]
    for i in range(m):
        for r in range(d.jstart[i], d.jstart[i + 1]):
            _scatter_stencil(d, i, r, -fac.alpha[r] * xt[i], xw)
    solve_banded_inplace(fac, xw)
    for i in range(m):
        ct = 0.0
        for r in range(d.jstart[i], d.jstart[i + 1]):
            ct += fac.alpha[r] * _stencil_dot(d, xw, i, r)
        cz = fac.bwz[i] * xw[i]
        xt[i] -= fac.p[i] * ct + fac.q[i] * cz
        xz[i] -= fac.q[i] * ct + fac.r[i] * cz


@inlined
def _v_into(
    sc: Scaling, pt: Point, rp: float, corrector: bool, sigma_mu: float, second_order: float,
    dn: Direction,
) -> None:
    """``v = H by - W⁻¹ u`` with ``λ ∘ u = bs``, into ``(dn.dyl, dn.dys)``.

    ``by`` is ``rp`` on the linear rows and zero on the cones; ``H = y / s`` on the linear
    rows. ``bs = -λ ∘ λ`` (the predictor), or with ``corrector`` Mehrotra's
    ``-λ ∘ λ - η (W⁻¹Δs) ∘ (WΔy) + σ μ e`` (``η`` = ``second_order``, see
    `SECOND_ORDER_EXPONENT`) for the predictor's direction, which ``dn`` holds on entry and
    which is overwritten entry by entry as it is read.
    """
    sl, yl, dsl, dyl = pt.sl, pt.yl, dn.dsl, dn.dyl
    for j in range(sl.size):
        bsl = -sl[j] * yl[j]  # λ∘λ = s y on the linear rows
        if corrector:
            bsl += sigma_mu - second_order * dsl[j] * dyl[j]
        dyl[j] = yl[j] / sl[j] * rp - bsl / sl[j]
    dys = dn.dys
    for c in range(dys.shape[1]):
        l0, l1, l2 = _lambda(sc, pt.ys, c)
        b0, b1, b2 = -(l0 ** 2 + l1 ** 2 + l2 ** 2), -2.0 * l0 * l1, -2.0 * l0 * l2
        if corrector:
            e0, e1, e2 = _cone_ds(dn.dw, dn.dt, dn.dz, c)
            a0, a1, a2 = _apply_winv(sc, e0, e1, e2, c)
            f0, f1, f2 = _apply_w(sc, dys[0, c], dys[1, c], dys[2, c], c)
            b0 += sigma_mu - second_order * (a0 * f0 + a1 * f1 + a2 * f2)
            b1 -= second_order * (a0 * f1 + f0 * a1)
            b2 -= second_order * (a0 * f2 + f0 * a2)
        u0, u1, u2 = _jordan_solve(l0, l1, l2, b0, b1, b2)
        w0, w1, w2 = _apply_winv(sc, u0, u1, u2, c)
        dys[0, c], dys[1, c], dys[2, c] = -w0, -w1, -w2


@inner
def _v_predictor_into(sc: Scaling, pt: Point, rp: float, dn: Direction) -> None:
    """`_v_into` of the predictor (``bs = -λ ∘ λ``)."""
    _v_into(sc, pt, rp, False, 0.0, 0.0, dn)


@inner
def _v_corrector_into(
    sc: Scaling, pt: Point, rp: float, sigma_mu: float, second_order: float, dn: Direction
) -> None:
    """`_v_into` of the corrector: compiled apart, so that neither loop tests ``corrector``.

    One kernel for both, testing it on every entry, made the whole iteration 10 % slower.
    """
    _v_into(sc, pt, rp, True, sigma_mu, second_order, dn)


@inner
def _recover_v_into(sc: Scaling, pt: Point, rp: float, dn: Direction) -> None:
    """Put back the ``v`` of `_v_into` into ``(dyl, dys)`` from the direction ``dn``.

    ``Δy = H G Δx - v`` with ``G Δx = by - Δs``: so ``v = H (by - Δs) - Δy`` on the linear
    rows and ``v = H G Δx - Δy`` on the cones, without the right-hand side ``bs``.
    """
    sl, yl, dsl, dyl = pt.sl, pt.yl, dn.dsl, dn.dyl
    for j in range(sl.size):
        dyl[j] = yl[j] / sl[j] * (rp - dsl[j]) - dyl[j]
    dys = dn.dys
    for c in range(dys.shape[1]):
        e0, e1, e2 = _cone_ds(dn.dw, dn.dt, dn.dz, c)
        h0, h1, h2 = _apply_h(sc, -e0, -e1, -e2, c)
        dys[0, c], dys[1, c], dys[2, c] = h0 - dys[0, c], h1 - dys[1, c], h2 - dys[2, c]


@inner
def _ds_dy_into(d: Data, sc: Scaling, pt: Point, rp: float, dn: Direction) -> None:
    """``Δs = by - G Δx`` (linear rows) and ``Δy = H G Δx - v``, with ``v`` in ``(dyl, dys)``."""
    g_lin_into(d, dn.dw, dn.dt, dn.dsl)  # G Δx, linear rows, kept in dsl until replaced
    sl, yl, dsl, dyl = pt.sl, pt.yl, dn.dsl, dn.dyl
    for j in range(sl.size):
        g = dsl[j]
        dyl[j] = yl[j] / sl[j] * g - dyl[j]
        dsl[j] = rp - g
    dys = dn.dys
    for c in range(dys.shape[1]):
        e0, e1, e2 = _cone_ds(dn.dw, dn.dt, dn.dz, c)
        h0, h1, h2 = _apply_h(sc, -e0, -e1, -e2, c)
        dys[0, c], dys[1, c], dys[2, c] = h0 - dys[0, c], h1 - dys[1, c], h2 - dys[2, c]


@inlined
def newton_into(
    d: Data, sc: Scaling, fac: Factor, pt: Point, res: Residual, rp: float,
    corrector: bool, sigma_mu: float, second_order: float, refine_above: float,
    dn: Direction,
) -> None:
    """Solve ``G'Δy = bx``, ``GΔx + Δs = by``, ``λ ∘ (WΔy + W⁻¹Δs) = bs`` into ``dn``.

    ``bx`` is the residual ``res``, which must be the iterate's (`dual_residual_into`:
    the refinement forms its own right-hand side in ``res``, then forms ``bx`` again from
    ``pt``), ``by`` is ``rp`` on the linear rows and zero on the cones,
    ``bs`` as `_v_into` says (``corrector``, ``sigma_mu``, ``second_order``; the corrector reads the
    predictor's direction from ``dn``). One round of iterative refinement follows if the
    2-norm of the residual ``bx - G'Δy`` exceeds ``refine_above`` (``inf``: no refinement,
    and the residual is not computed).
    """
    # With v = H by - W⁻¹ u (λ ∘ u = bs): (G'HG) Δx = bx + G' v and Δy = H G Δx - v.
    if corrector:
        _v_corrector_into(sc, pt, rp, sigma_mu, second_order, dn)
    else:
        _v_predictor_into(sc, pt, rp, dn)
    for i in range(dn.dw.size):  # loops, not slice assignments: they cost seconds to compile
        dn.dw[i], dn.dt[i], dn.dz[i] = res.gw[i], res.gt[i], res.gz[i]
    g_adjoint_into(d, dn.dyl, dn.dys, dn.dw, dn.dt, dn.dz, ADJ_ADD)
    solve_normal_inplace(d, fac, dn.dw, dn.dt, dn.dz)
    _ds_dy_into(d, sc, pt, rp, dn)
    # The last two equations hold by construction; only G'Δy = bx inherits the rounding of
    # the reduced solve, which grows as H becomes ill-conditioned near the optimum. A round
    # of iterative refinement with the same factor restores it.
    if refine_above < np.inf:
        # The residual bx - G'Δy is formed in res itself, and bx formed again from the
        # iterate afterwards (it is a function of pt alone): no array of its own.
        rw, rt, rz = res.gw, res.gt, res.gz
        g_adjoint_into(d, dn.dyl, dn.dys, rw, rt, rz, ADJ_SUBTRACT)
        res2 = 0.0
        for i in range(rw.size):
            res2 += rw[i] * rw[i] + rt[i] * rt[i] + rz[i] * rz[i]
        if math.sqrt(res2) > refine_above:
            solve_normal_inplace(d, fac, rw, rt, rz)
            _recover_v_into(sc, pt, rp, dn)  # the same v, from the unrefined direction
            for i in range(rw.size):
                dn.dw[i] += rw[i]
                dn.dt[i] += rt[i]
                dn.dz[i] += rz[i]
            _ds_dy_into(d, sc, pt, rp, dn)
        dual_residual_into(d, pt, res)


# --- the iteration, step by step ------------------------------------------------------------


@inner
def _dot(a: FloatArray, b: FloatArray) -> float:
    """``a · b`` of two vectors, without a temporary."""
    acc = 0.0
    for i in range(a.size):
        acc += a[i] * b[i]
    return acc


@inner
def _dot2(a: FloatArray, b: FloatArray) -> float:
    """``a · b`` over all entries of two 2-D arrays, row by row (as `_dot` of them flat)."""
    acc = 0.0
    for r in range(a.shape[0]):
        for c in range(a.shape[1]):
            acc += a[r, c] * b[r, c]
    return acc


@inner
def _axpy(alpha: float, x: FloatArray, y: FloatArray) -> None:
    """``y += α x`` in place, for vectors."""
    for i in range(x.size):
        y[i] += alpha * x[i]


@inner
def _axpy2(alpha: float, x: FloatArray, y: FloatArray) -> None:
    """``y += α x`` in place, for 2-D arrays."""
    for r in range(x.shape[0]):
        for c in range(x.shape[1]):
            y[r, c] += alpha * x[r, c]


@inner
def _shift(worst: float, nrm: float) -> float:
    """Return CVXOPT's initial-point shift along ``e``.

    The shift is ``1 + t`` (``t = -worst``, the most negative entry) when ``u`` is not
    interior by margin, else 0.
    """
    ts = -worst
    return 1.0 + ts if ts >= -1e-8 * max(nrm, 1.0) else 0.0


@inner
def _shift_into_cone(ul: FloatArray, us: FloatArray) -> None:
    """Add `_shift` of ``(ul, us)`` to every linear entry and every cone's axis."""
    worst = np.inf
    for i in range(ul.size):
        worst = min(worst, ul[i])
    for c in range(us.shape[1]):
        worst = min(worst, us[0, c] - math.hypot(us[1, c], us[2, c]))
    shift = _shift(worst, math.sqrt(_dot(ul, ul) + _dot2(us, us)))
    for i in range(ul.size):
        ul[i] += shift
    for c in range(us.shape[1]):
        us[0, c] += shift


@inlined
def start_into(
    d: Data, sc: Scaling, fac: Factor, pt: Point, dn: Direction
) -> tuple[bool, float]:
    """Slacks and multipliers of the start, given the primal point ``(w, t, z)`` in ``pt``.

    ``s = b - G x``, with the linear rows shifted into the orthant by CVXOPT's rule (the
    cones' slacks are not shifted: they stay ``b - G x``, see `Point`), and CVXOPT's
    default dual start (least-norm ``y`` of ``G' y = -c``, with ``W = I``) shifted into the
    cones. ``sc`` must be the identity scaling. Returns whether ``b - G x`` is strictly
    inside every cone (else nothing else is valid) and the linear rows' primal residual
    ``rp`` (minus their shift).
    """
    m = d.lay.m
    for c in range(2 * m):
        s0, s1, s2 = _cone_s(pt.w, pt.t, pt.z, c)
        if not _interior(s0, s1, s2):
            return False, 0.0
    for j in range(pt.sl.size):  # W = I on the linear rows: y / s = 1
        pt.sl[j] = 1.0
        pt.yl[j] = 1.0
    factor_into(d, sc, pt.yl, pt.sl, fac)
    g_lin_into(d, pt.w, pt.t, pt.sl)
    worst = np.inf
    for j in range(pt.sl.size):
        pt.sl[j] = _b_lin(d, j) - pt.sl[j]
        worst = min(worst, pt.sl[j])
    shift = _shift(worst, math.sqrt(_dot(pt.sl, pt.sl)))
    for j in range(pt.sl.size):
        pt.sl[j] += shift
    for i in range(m):
        dn.dw[i] = 0.0
        dn.dt[i] = -d.ct[i]
        dn.dz[i] = 0.0
    solve_normal_inplace(d, fac, dn.dw, dn.dt, dn.dz)
    g_lin_into(d, dn.dw, dn.dt, pt.yl)
    g_soc_into(dn.dw, dn.dt, dn.dz, pt.ys)
    _shift_into_cone(pt.yl, pt.ys)
    return True, -shift


@inlined
def dual_residual_into(d: Data, pt: Point, res: Residual) -> float:
    """The dual residual, negated, ``-(G'y + c)``, into ``res``; returns its squared norm."""
    sw, st, sz = g_adjoint_into(d, pt.yl, pt.ys, res.gw, res.gt, res.gz, ADJ_DUAL_RESIDUAL)
    return sw + st + sz


@inner
def residuals_into(
    d: Data, pt: Point, res: Residual, scratch: FloatArray
) -> tuple[float, float, float, float, float]:
    """Dual residual (negated) into ``res``; returns ``(pcost, dcost, gap, |r_y|², |r_x|²)``.

    ``|r_y|²`` is the linear rows' primal residual ``b - G x - s`` of the iterate itself,
    computed in ``scratch`` (the cones have none, see `Point`).
    """
    m = d.lay.m
    rx2 = dual_residual_into(d, pt, res)
    g_lin_into(d, pt.w, pt.t, scratch)
    sl, yl = pt.sl, pt.yl
    ry2 = gap = yb = 0.0  # one pass over the linear rows for |r_y|², s'y and y'b
    for j in range(scratch.size):
        b = _b_lin(d, j)
        r = b - scratch[j] - sl[j]
        ry2 += r * r
        gap += sl[j] * yl[j]
        yb += yl[j] * b
    ys = pt.ys
    ys_b = 0.0  # ys · b_soc with the constant part of the cone rows spelled out
    for c in range(2 * m):
        s0, s1, s2 = _cone_s(pt.w, pt.t, pt.z, c)
        gap += s0 * ys[0, c] + s1 * ys[1, c] + s2 * ys[2, c]
        if c < m:
            ys_b += ys[0, c] - ys[2, c] + 2.0 * ys[2, m + c]
    pcost = _dot(d.ct, pt.t)
    dcost = -yb - ys_b
    return pcost, dcost, gap, ry2, rx2


@inlined
def _max_steps(pt: Point, dn: Direction) -> tuple[float, float]:
    """Largest steps along ``dn`` keeping ``s`` (primal) and ``y`` (dual) in their cones."""
    return (min(max_step_lin(pt.sl, dn.dsl), max_step_slack_soc(pt, dn)),
            min(max_step_lin(pt.yl, dn.dyl), max_step_soc(pt.ys, dn.dys)))


@inlined
def step(pt: Point, dn: Direction) -> tuple[float, float]:
    """Move ``pt`` along ``dn``: the primal and the dual variables each a fraction ``STEP``.

    Each goes that fraction of the way to its cones' boundary (at most a full step); returns
    the two steps ``(α_primal, α_dual)``. Taking them apart, as SDPT3 does, keeps one side's
    nearest boundary from holding back the other: ``(x, s)`` move by ``α_primal`` (so the
    linear rows' primal residual shrinks by ``1 - α_primal``), the multipliers ``y`` by
    ``α_dual``; the dual residual is formed from the iterate at every iteration. On plan()
    grids it saves about a tenth of the iterations on top of the corrector's weighting
    (`SECOND_ORDER_EXPONENT`, docs/banded-ipm.md). The closed-form step to the boundary can
    be off by rounding for nearly degenerate cones; a side's step is halved until its cones
    are strictly interior. Returns ``(0, 0)`` (nothing moved) if no such steps were found.
    """
    to_primal, to_dual = _max_steps(pt, dn)
    alpha, alpha_dual = min(1.0, STEP * to_primal), min(1.0, STEP * to_dual)
    if not (math.isfinite(alpha) and alpha > 0.0 and math.isfinite(alpha_dual)
            and alpha_dual > 0.0):
        return 0.0, 0.0
    inside = False
    for _ in range(30):
        primal, dual = _interior_after_step(pt, alpha, alpha_dual, dn)
        if primal and dual:
            inside = True
            break
        if not primal:
            alpha *= 0.5
        if not dual:
            alpha_dual *= 0.5
    if not inside:
        return 0.0, 0.0
    _axpy2(alpha_dual, dn.dys, pt.ys)
    _axpy(alpha, dn.dw, pt.w)
    _axpy(alpha, dn.dt, pt.t)
    _axpy(alpha, dn.dz, pt.z)
    _axpy(alpha, dn.dsl, pt.sl)
    _axpy(alpha_dual, dn.dyl, pt.yl)
    return alpha, alpha_dual


@inner
def _residual_scales(d: Data) -> tuple[float, float]:
    """The scales of the relative dual and primal residuals, ``(max(1, sqrt(m)), max(1, |b|))``.

    ``|b|`` is the norm of the right-hand side of every row, linear and cone.
    """
    lay = d.lay
    b_soc2 = 0.0  # |b_soc|², entries in storage order
    for r in range(3):
        for c in range(lay.nc):
            b_soc2 += _b_soc(r, c, lay.m) * _b_soc(r, c, lay.m)
    b_lin2 = 0.0
    for j in range(lay.n_lin):
        b = _b_lin(d, j)
        b_lin2 += b * b
    return max(1.0, math.sqrt(lay.m)), max(1.0, math.sqrt(b_lin2 + b_soc2))


@kernel
def iterate(
    d: Data, pt: Point, res: Residual, dn: Direction, sc: Scaling, fac: Factor,
    log: FloatArray, tol: float, max_iter: int,
) -> tuple[int, int]:
    """Mehrotra predictor–corrector iterations from the primal point ``(w, t, z)`` in ``pt``.

    ``sc`` must be the identity scaling. The iterate is updated in place (internal units);
    returns ``(iterations, status)`` with one of the module's status codes. Row ``k`` of
    ``log`` (shape ``(max_iter + 1, len(LOG_COLUMNS))``) records iteration ``k``.
    """
    lay = d.lay
    ok, rp = start_into(d, sc, fac, pt, dn)
    if not ok:
        return 0, NUMERICAL_ERROR
    res_x0, res_y0 = _residual_scales(d)
    nu = lay.n_lin + lay.nc  # barrier degree: one per linear row and per cone
    status = MAX_ITERATIONS
    it = 0
    best_gap, stalled = np.inf, 0
    best_pres, best_dres, jammed = np.inf, np.inf, 0
    for it in range(max_iter + 1):
        pcost, dcost, gap, ry2, rx2 = residuals_into(d, pt, res, dn.dsl)
        pres = math.sqrt(ry2) / res_y0
        dres = math.sqrt(rx2) / res_x0
        relgap = gap / max(min(abs(pcost), abs(dcost)), 1e-300)
        log[it, 0], log[it, 1], log[it, 2], log[it, 3] = pcost, dcost, relgap, pres
        log[it, 4] = dres
        if pres <= tol and dres <= tol and relgap <= tol:
            status = SOLVED
            break
        # Near the optimum the NT scaling becomes ill-conditioned and rounding may stop
        # progress short of ``tol``; detect that instead of spinning to ``max_iter``. The gap
        # s'y may round to a tiny negative number once it has converged; clamped at 0, it
        # then counts as no further progress (unclamped, every negative value "halved" the
        # previous one and the method ran to max_iter, seen on a 20 000-node grid).
        moved = False  # the gap or a residual halved since it last did
        if max(relgap, 0.0) < 0.5 * best_gap:
            best_gap, stalled, moved = max(relgap, 0.0), 0, True
        else:
            stalled += 1
        if stalled >= STALL_ITERATIONS and best_gap < ALMOST_GAP:
            status = STALLED
            break
        if pres < 0.5 * best_pres:
            best_pres, moved = pres, True
        if dres < 0.5 * best_dres:
            best_dres, moved = dres, True
        jammed = 0 if moved else jammed + 1
        if jammed >= NO_PROGRESS_ITERATIONS:
            status = NO_PROGRESS
            break
        if it == max_iter:
            break
        if not (math.isfinite(pres) and math.isfinite(dres) and math.isfinite(gap)):
            status = NUMERICAL_ERROR
            break
        scaling_into(pt, sc)
        if not factor_into(d, sc, pt.yl, pt.sl, fac):
            status = NUMERICAL_ERROR
            break
        # Refinement only pays once the scaling is ill-conditioned, close to the optimum, and
        # only where the solve's own residual could show in the dual residual's test.
        refine_above = REFINE_RESIDUAL * tol * res_x0 if relgap < REFINE_BELOW else np.inf
        # Predictor: the affine-scaling direction (right-hand side -λ∘λ), whose largest step
        # sets Mehrotra's σ and the weight of the corrector's second-order term; then the
        # corrector: that term and centring σ μ.
        # One call in a loop: numba inlines newton_into, and one copy compiles faster.
        sigma = sigma_mu = second_order = 0.0
        for corrector in range(2):
            newton_into(d, sc, fac, pt, res, rp, corrector == 1, sigma_mu, second_order,
                        refine_above, dn)
            if corrector == 0:
                to_primal, to_dual = _max_steps(pt, dn)
                reach = min(1.0, to_primal, to_dual)
                sigma = (1.0 - reach) ** SIGMA_EXPONENT
                sigma_mu = sigma * (gap / nu)
                second_order = reach ** SECOND_ORDER_EXPONENT
        alpha, alpha_dual = step(pt, dn)
        rp *= 1.0 - alpha  # G Δx + Δs = by: the primal step removes the fraction α of it
        log[it, 5], log[it, 6], log[it, 7] = sigma, alpha, alpha_dual
        if alpha == 0.0:
            status = NUMERICAL_ERROR
            break
    return it, status


#: The kernels called from Python (the others are called only from compiled code).
ENTRY_POINTS = ("iterate",)


def signatures() -> dict[str, tuple[Any, ...]]:
    """Every kernel of the module and its one signature, each after the kernels it calls.

    `speedplan.core.jit` compiles them in this order, each for exactly this signature, and
    then refuses any other: a caller passing a constant (``ADJ_ADD``, ``False``) uses the
    kernel compiled for its type instead of compiling a copy specialised to the value.
    The types are those of `iterate`'s arguments as `speedplan.solve.banded` builds them,
    so the arrays here are of the smallest sizes.
    """
    import numba
    from numba import types as nt

    lay = layout(1, 1, 0)
    data = Data(jstart=np.zeros(2, dtype=np.intp), jc=np.zeros((3, 1)), cj=np.zeros(1),
                lk=np.zeros(0, dtype=np.intp), ct=np.zeros(1), cw=np.zeros(1),
                b_lin=np.zeros(lay.jm), lay=lay)
    d, pt, res, dn, sc, fac = (numba.typeof(a) for a in (  # type: ignore[no-untyped-call]
        data, empty(Point, lay), empty(Residual, lay), empty(Direction, lay),
        Scaling.identity(lay), empty(Factor, lay)))
    v, mat, i, x = nt.float64[::1], nt.float64[:, ::1], nt.intp, nt.float64
    return {
        "_pad": (v, i), "_b_lin": (d, i), "_stencil_dot": (d, v, i, i),
        "_scatter_stencil": (d, i, i, x, v), "_jnorm2": (x, x, x), "_h_entries": (sc, i),
        "_apply_h": (sc, x, x, x, i), "_apply_w": (sc, x, x, x, i),
        "_apply_winv": (sc, x, x, x, i), "_jordan_solve": (x, x, x, x, x, x),
        "_b_soc": (i, i, i), "_cone_s": (v, v, v, i), "_cone_ds": (v, v, v, i),
        "g_lin_into": (d, v, v, v), "g_soc_into": (v, v, v, mat),
        "g_adjoint_into": (d, v, mat, v, v, v, i), "_cone_step": (x, x, x, x, x, x),
        "max_step_soc": (mat, mat), "max_step_slack_soc": (pt, dn), "max_step_lin": (v, v),
        "_interior": (x, x, x), "_interior_after_step": (pt, x, x, dn),
        "cone_scaling_into": (sc, i, x, x, x, x, x, x), "scaling_into": (pt, sc),
        "_lambda": (sc, mat, i), "_eliminate_tz": (d, sc, v, v, fac, i),
        "factor_into": (d, sc, v, v, fac), "solve_banded_inplace": (fac, v),
        "solve_normal_inplace": (d, fac, v, v, v), "_v_predictor_into": (sc, pt, x, dn),
        "_v_corrector_into": (sc, pt, x, x, x, dn),
        "_recover_v_into": (sc, pt, x, dn), "_ds_dy_into": (d, sc, pt, x, dn),
        "_dot": (v, v), "_dot2": (mat, mat), "_axpy": (x, v, v), "_axpy2": (x, mat, mat),
        "_shift": (x, x), "_shift_into_cone": (v, mat),
        "residuals_into": (d, pt, res, v), "_residual_scales": (d,),
        "iterate": (d, pt, res, dn, sc, fac, mat, x, i),
    }


def python_callable(fn: Any) -> Any:
    """``fn`` (any kernel of this module) callable from Python: for tests and diagnostics.

    The kernels other than `iterate` have no Python entry point (see
    `speedplan.core.jit.inner`); this wraps one in a compiled trampoline (compiled on first
    call, not cached) with the kernel's own parameters (numba inlines an
    `speedplan.core.jit.inlined` kernel, which takes no ``*args``).

    Examples
    --------
    >>> import numpy as np
    >>> python_callable(max_step_lin)(np.ones(3), -np.ones(3))
    1.0
    """
    if fn not in _TRAMPOLINES:
        params = ", ".join(inspect.signature(fn.py_func).parameters)
        scope: dict[str, Any] = {"kernel": fn}
        exec(f"def call({params}):\n    return kernel({params})\n", scope)
        _TRAMPOLINES[fn] = njit(scope["call"])
    return _TRAMPOLINES[fn]


_TRAMPOLINES: dict[Any, Any] = {}

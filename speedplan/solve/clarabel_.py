"""SOCP relaxation of the discrete problem through Clarabel's native API.

Variables ``x = [w (n), t (m), z (m)]`` with ``m = n - 2`` interior nodes. The paper's
relaxation ``t_i >= τ_i / sqrt(w_i)``, ``t_i >= ±τ_i w''_i / J_i`` becomes two 3-D second-order
cones per node: ``z² <= w`` as ``||(2z, w - 1)|| <= w + 1`` and ``t z >= τ`` as
``||(2 sqrt(τ), t - z)|| <= t + z`` (one cone fewer than the paper's three). The whole matrix is
assembled with vectorised numpy in COO form.

Friction-ellipse rows (`DiscreteProblem.grip`) add one variable per cell, ``u_i`` at
least the cell's acceleration and braking as fractions of their limits (two linear rows),
and two 3-D cones per cell, ``||(u_i, g_j w_j)|| <= 1`` at either end ``j``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import clarabel
import numpy as np

from ..core.checks import FloatArray, IntArray
from ..core.deadline import MIN_SOLVER_TIME, remaining
from ..core.errors import InfeasibleError, SolverError
from .cuts import SecantCuts
from .problem import DiscreteProblem

if TYPE_CHECKING:  # scipy.sparse is imported where the SOCP is built: import speedplan stays light
    import scipy.sparse as sp

__all__ = ["RelaxationResult", "row_multipliers", "solve_relaxation"]

_SOLVED = {"Solved"}
_ALMOST = {"AlmostSolved"}
_INFEASIBLE = {"PrimalInfeasible", "AlmostPrimalInfeasible"}
_STALLED = {"InsufficientProgress", "MaxIterations", "NumericalError"}


@dataclass(frozen=True)
class RelaxationResult:
    """Raw result of one relaxation solve (in the problem's own units)."""

    w: FloatArray
    t: FloatArray
    primal_objective: float
    dual_objective: float
    status: str
    iterations: int
    solve_time: float
    setup_time: float
    z: FloatArray | None = None  # Clarabel's dual variables, in the rows' order (build_socp)


def _rows(
    n_rows: int, cols: list[Any], vals: list[Any]
) -> tuple[IntArray, IntArray, FloatArray]:
    """Row, column and value arrays of ``n_rows`` rows with one entry per ``cols`` item."""
    k = len(cols)
    r: IntArray = np.repeat(np.arange(n_rows), k)
    c: IntArray = np.column_stack(cols).ravel()
    v: FloatArray = np.column_stack(vals).ravel().astype(np.float64)
    return r, c, v


class _Rows:
    """Rows of ``A x + s = b`` gathered block by block, in cone order."""

    def __init__(self) -> None:
        self.r: list[IntArray] = []
        self.c: list[IntArray] = []
        self.v: list[FloatArray] = []
        self.b: list[FloatArray] = []
        self.count = 0

    def add(self, n_rows: int, cols: list[Any], vals: list[Any], rhs: FloatArray) -> None:
        """``n_rows`` rows, one entry per row from each column and value array."""
        r, c, v = _rows(n_rows, cols, vals)
        self.add_coo(np.asarray(r), np.asarray(c), np.asarray(v), rhs)

    def add_coo(self, r: IntArray, c: IntArray, v: FloatArray, rhs: FloatArray) -> None:
        """Rows given as coordinates ``r`` (from 0), ``c`` and values ``v``."""
        self.r.append(r + self.count)
        self.c.append(c)
        self.v.append(v)
        self.b.append(rhs)
        self.count += rhs.size

    def matrix(self, nvar: int) -> tuple[sp.csc_matrix, FloatArray]:
        import scipy.sparse as sp

        A = sp.csc_matrix((np.concatenate(self.v), (np.concatenate(self.r),
                                                    np.concatenate(self.c))),
                          shape=(self.count, nvar))
        return A, np.concatenate(self.b)


def build_socp(problem: DiscreteProblem, cuts: SecantCuts | None = None
               ) -> tuple[sp.csc_matrix, FloatArray, FloatArray, list[Any]]:
    """Return ``(A, b, q, cones)`` of the relaxation in Clarabel's ``Ax + s = b`` form.

    Variables: ``w`` (n), the epigraph ``t`` and auxiliary ``z`` of each interior node
    (``t_i >= τ_i / sqrt(w_i)`` through ``z_i² <= w_i`` and ``t_i z_i >= τ_i``), and with a
    friction ellipse each cell's acceleration fraction ``u``. ``cuts`` (`secant_cuts`) adds
    its linear rows.
    """
    n = problem.n
    m = n - 2
    iw, it, iz, iu = 0, n, n + m, n + 2 * m
    nvar = n + 2 * m + (n - 1 if problem.has_grip else 0)
    h = problem.h
    interior = np.arange(1, n - 1)
    seg = np.arange(n - 1)
    rows = _Rows()
    one = np.ones
    # Zero cone: the two boundary values.
    rows.add(2, [np.array([iw, iw + n - 1])], [one(2)], np.array([problem.w_start, problem.w_end]))
    # Nonnegative cone: acceleration, braking, upper bounds, jerk rows.
    rows.add(n - 1, [iw + seg + 1, iw + seg], [one(n - 1), -one(n - 1)], problem.accel * h)
    rows.add(n - 1, [iw + seg, iw + seg + 1], [one(n - 1), -one(n - 1)], problem.decel * h)
    rows.add(m, [iw + interior], [one(m)], problem.w_max[1:-1])
    if problem.has_lower_bounds:
        assert problem.w_min is not None
        low = np.flatnonzero(problem.w_min[1:-1] > 0) + 1
        rows.add(low.size, [iw + low], [-one(low.size)], -problem.w_min[low])
    _add_stencil_rows(rows, problem, iw, it)
    if problem.has_grip:  # (±(w_{i+1} - w_i) / (h A)) - u_i <= 0
        ucol = iu + seg
        for lo_col, hi_col, limit in ((iw + seg, iw + seg + 1, problem.accel),
                                      (iw + seg + 1, iw + seg, problem.decel)):
            rows.add(n - 1, [hi_col, lo_col, ucol],
                     [1.0 / (h * limit), -1.0 / (h * limit), -one(n - 1)], np.zeros(n - 1))
    if cuts is not None and cuts.size:
        i = iw + cuts.node
        rows.add(cuts.size, [i - 1, i, i + 1], [cuts.coef[:, 0], cuts.coef[:, 1], cuts.coef[:, 2]],
                 cuts.rhs)
    n_nonneg = rows.count - 2
    _add_node_cones(rows, problem.tau, iw, it, iz)
    n_grip_cones = 0
    if problem.grip is not None:
        r, c, v, rhs = _grip_cones(problem.grip, iw, iu)
        rows.add_coo(r, c, v, rhs)
        n_grip_cones = rhs.size // 3
    A, b = rows.matrix(nvar)
    q = np.zeros(nvar)
    q[it : it + m] = 1.0
    cones = [clarabel.ZeroConeT(2), clarabel.NonnegativeConeT(n_nonneg)]
    cones += [clarabel.SecondOrderConeT(3)] * (2 * m + n_grip_cones)
    return A, b, q, cones


def row_multipliers(problem: DiscreteProblem, z: FloatArray, cuts: SecantCuts | None = None
                    ) -> tuple[FloatArray, FloatArray, list[tuple[FloatArray, FloatArray]],
                               FloatArray]:
    """Clarabel's multipliers of the rows of `build_socp`, by kind.

    Returns ``(μ_acc, μ_dec, [(ν⁺_f, ν⁻_f) per family, per interior node], π_cuts)``, in the
    order `build_socp` lays the rows out (the bounds' rows and the cones are left out: a
    Lagrangian bound takes the bounds as its box).
    """
    n, m = problem.n, problem.n - 2
    k = 2
    mu_acc, k = z[k:k + n - 1], k + n - 1
    mu_dec, k = z[k:k + n - 1], k + n - 1
    k += m
    if problem.has_lower_bounds:
        assert problem.w_min is not None
        k += int(np.count_nonzero(problem.w_min[1:-1] > 0))
    nu = []
    for family in problem.stencil_families():
        finite = np.flatnonzero(np.isfinite(family.bound))
        plus, minus = np.zeros(m), np.zeros(m)
        plus[finite], k = z[k:k + finite.size], k + finite.size
        minus[finite], k = z[k:k + finite.size], k + finite.size
        nu.append((plus, minus))
    if problem.has_grip:
        k += 2 * (n - 1)
    size = 0 if cuts is None else cuts.size
    return mu_acc, mu_dec, nu, z[k:k + size]


def _add_stencil_rows(rows: _Rows, problem: DiscreteProblem, iw: int, it: int) -> None:
    """The relaxed jerk and lateral-jerk rows ``±τ (c·w) / B - t <= 0`` (nonnegative cone)."""
    tau = problem.tau
    m = problem.n - 2
    wcols = (np.arange(m)[:, None] + np.arange(3)[None, :]) + iw
    for family in problem.stencil_families():  # jerk rows, then lateral-jerk rows
        finite = np.flatnonzero(np.isfinite(family.bound))
        if not finite.size:
            continue
        coef = np.asarray(family.coef)[finite] * (tau[finite] / family.bound[finite])[:, None]
        cols = wcols[finite]
        tcol = (it + finite)[:, None]
        k = finite.size
        for sign in (1.0, -1.0):
            rows.add(
                k,
                [cols[:, 0], cols[:, 1], cols[:, 2], tcol[:, 0]],
                [sign * coef[:, 0], sign * coef[:, 1], sign * coef[:, 2], -np.ones(k)],
                np.zeros(k),
            )


def _add_node_cones(rows: _Rows, tau: FloatArray, iw: int, it: int, iz: int) -> None:
    """Second-order cones, interleaved per node: (w+1, 2z, w-1) and (t+z, t-z, 2 sqrt(τ))."""
    m = tau.size
    j = np.arange(m)
    wc, tc, zc = iw + 1 + j, it + j, iz + j
    r = np.column_stack((6 * j, 6 * j + 1, 6 * j + 2, 6 * j + 3, 6 * j + 3, 6 * j + 4, 6 * j + 4))
    c = np.column_stack((wc, zc, wc, tc, zc, tc, zc))
    v = np.tile([-1.0, -2.0, -1.0, -1.0, -1.0, -1.0, 1.0], (m, 1))
    rhs = np.zeros((m, 6))
    rhs[:, 0], rhs[:, 2], rhs[:, 5] = 1.0, -1.0, 2.0 * np.sqrt(tau)
    rows.add_coo(r.ravel(), c.ravel(), v.ravel(), rhs.ravel())


def _grip_cones(grip: FloatArray, iw: int, iu: int
                ) -> tuple[IntArray, IntArray, FloatArray, FloatArray]:
    """Rows, columns, values and right-hand side of the cones ``(1, u_i, g_j w_j)``.

    Two per cell ``i``, at its ends ``j = i, i + 1``; ``iw`` and ``iu`` are the first columns
    of ``w`` and ``u``.
    """
    seg = np.arange(grip.size - 1)
    k = 2 * seg.size
    cell = np.concatenate((seg, seg))
    node = np.concatenate((seg, seg + 1))
    rows = np.column_stack((3 * np.arange(k) + 1, 3 * np.arange(k) + 2)).ravel()
    cols = np.column_stack((iu + cell, iw + node)).ravel()
    vals = np.column_stack((-np.ones(k), -grip[node])).ravel()
    rhs = np.zeros((k, 3))
    rhs[:, 0] = 1.0
    return rows, cols, vals, rhs.ravel()


def default_settings() -> clarabel.DefaultSettings:
    """Clarabel settings used by `solve_relaxation` (printing off, default tolerances)."""
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.max_iter = 200
    return settings


def retry_settings() -> clarabel.DefaultSettings:
    """Settings of the second attempt after a stall: no equilibration, more iterations."""
    settings = default_settings()
    settings.equilibrate_enable = False
    settings.max_iter = 400
    return settings


def _within_deadline(settings: clarabel.DefaultSettings) -> clarabel.DefaultSettings:
    """``settings`` stopping at the plan's deadline, if any (`deadline`)."""
    left = remaining()
    if left is not None:
        settings.time_limit = min(float(settings.time_limit), left)
    return settings


def _run(P: sp.csc_matrix, q: FloatArray, A: sp.csc_matrix, b: FloatArray, cones: list[Any],
         settings: clarabel.DefaultSettings) -> Any:
    try:
        return clarabel.DefaultSolver(P, q, A, b, cones, settings).solve()
    except Exception as exc:  # the Rust core raises plain exceptions on bad data
        raise SolverError(f"Clarabel failed: {exc}", backend="clarabel") from exc


def solve_relaxation(
    problem: DiscreteProblem, settings: clarabel.DefaultSettings | None = None,
    cuts: SecantCuts | None = None, *, time_limit: float | None = None,
) -> RelaxationResult:
    """Solve the SOCP relaxation (with ``cuts``, if given); raise on infeasibility or failure.

    ``time_limit`` [s]: Clarabel stops there and its last iterate is returned with status
    ``"MaxTime"`` (its multipliers still give a valid bound by weak duality) instead of
    raising.
    """
    import scipy.sparse as sp

    t0 = time.perf_counter()
    A, b, q, cones = build_socp(problem, cuts)
    P = sp.csc_matrix((q.size, q.size))
    t1 = time.perf_counter()
    end = None if time_limit is None else t1 + time_limit

    def limited(s: clarabel.DefaultSettings) -> clarabel.DefaultSettings:
        s = _within_deadline(s)
        if end is not None:
            s.time_limit = min(float(s.time_limit),
                               max(end - time.perf_counter(), MIN_SOLVER_TIME))
        return s

    first = settings or default_settings()
    sol = _run(P, q, A, b, cones, limited(first))
    status = str(sol.status)
    if status in _STALLED and settings is None:
        # Measured on fuzzed instances (long graded grids with lower bounds): Clarabel's
        # equilibration can stall the iteration; without it the same problem solves.
        sol = _run(P, q, A, b, cones, limited(retry_settings()))
        status = str(sol.status)
    t2 = time.perf_counter()
    stopped = time_limit is not None and status == "MaxTime"
    if status in _INFEASIBLE:
        raise InfeasibleError(
            "the relaxation is infeasible: no speed law meets the boundary values together "
            "with the acceleration and jerk bounds",
            constraint="jerk",
        )
    if status not in _SOLVED | _ALMOST and not stopped:
        raise SolverError(
            f"Clarabel stopped with status {status} after {sol.iterations} iterations",
            backend="clarabel",
            status=status,
        )
    x = np.asarray(sol.x)
    n, m = problem.n, problem.n - 2
    return RelaxationResult(
        z=np.asarray(sol.z, dtype=np.float64),
        w=x[:n].copy(),
        t=x[n : n + m].copy(),
        primal_objective=float(sol.obj_val),
        dual_objective=float(sol.obj_val_dual),
        status=status,
        iterations=int(sol.iterations),
        solve_time=t2 - t1,
        setup_time=t1 - t0,
    )

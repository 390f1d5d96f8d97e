"""The discrete speed-planning problem on a (possibly non-uniform) grid.

With ``w = v²`` sampled at nodes ``s_0 < … < s_{n-1}`` (steps ``h_i``), the problem is

    minimise   Σ_interior τ_i / sqrt(w_i)                    (τ_i = (h_{i-1} + h_i) / 2)
    subject to (w_{i+1} - w_i) / h_i <= A_i,   (w_i - w_{i+1}) / h_i <= D_i,
               0 <= w_i <= w_max_i,   w_0 = w_start,   w_{n-1} = w_end,
               |w''_i| sqrt(w_i) <= J_i      (w'' the three-point second difference).

On a uniform grid it is the paper's problem verbatim (``Σ h/sqrt(w_i)`` and
``|w_{i-1} - 2 w_i + w_{i+1}| sqrt(w_i) <= h² J``).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from ..core.checks import FloatArray
from ..core.rates import largest_under_rates

if TYPE_CHECKING:
    import scipy.sparse as sp

__all__ = ["MAX_RAMP_STEPS", "ROW_TOL_REL", "DiscreteProblem", "StencilRows", "ramp_steps"]

#: Paper's exactness test: a jerk row may be violated by at most 1e-5 (``h = 1``, ``w_max``
#: up to 100). We apply it relative to the largest bound, which is the same number at the
#: paper's scale and makes the test invariant when ``w`` is rescaled.
JERK_TOL = 1e-5
JERK_TOL_REL = JERK_TOL / 100.0
#: ... and by at most this fraction of the row's own bound. The paper's measure is in units of
#: ``w`` (``τ² (|w''| - J / sqrt(w))``), which shrinks with the square of the step: on a fine
#: grid a relaxed point whose jerk exceeds a row by 14 % passed it (comfort plans of 20 000
#: nodes, whose law then broke the jerk limit 1.14× and no refinement of the grid helped).
#: Exact relaxed points of the latency fuzz's curved, zone and comfort plans stay within
#: 0.16 % of their rows (the interior-point methods' accuracy); the inexact ones were 2–14 %
#: over.
ROW_TOL_REL = 1e-2
#: Largest excess of the friction-ellipse rows over 1 a solution may have: an interior-point
#: method meets a cone to its own tolerance (Clarabel's answers: up to 1.5e-6, measured on an
#: arc), 1e-5 of the grip is far inside what ``verify()`` tolerates (1 %).
GRIP_TOL = 1e-5


@dataclass(frozen=True)
class StencilRows:
    """Rows ``|c0_i w_{i-1} + c1_i w_i + c2_i w_{i+1}| sqrt(w_i) <= bound_i`` at interior nodes.

    The structure of the jerk rows (whose stencil is the second difference): a linear form of
    three neighbouring ``w`` times ``sqrt(w_i)``, relaxed the same way with the same epigraph
    variable ``t_i >= τ_i / sqrt(w_i)``, ``t_i >= ±τ_i (c_i · w) / bound_i``. Lateral jerk
    ``d(κ v²)/dt = sqrt(w) (κ' w + κ w')`` has it.

    Attributes
    ----------
    coef : ndarray, shape (n-2, 3)
        Stencil of each interior node, in units of ``1/m²`` (``c · w`` has the units of
        ``w''``).
    bound : ndarray, shape (n-2,)
        Bound of each row [m/s³] (> 0); ``inf`` drops the row.
    """

    coef: FloatArray
    bound: FloatArray

    def scaled(self, s_scale: float, w_scale: float) -> StencilRows:
        """The rows in units ``s/s_scale`` and ``w/w_scale`` (as `DiscreteProblem.scaled`)."""
        return StencilRows(coef=self.coef * s_scale**2,
                           bound=self.bound * s_scale**2 / w_scale**1.5)


@dataclass(frozen=True)
class DiscreteProblem:
    """Data of one discrete problem; arrays are validated by the callers' checks.

    Attributes
    ----------
    s : ndarray, shape (n,)
        Strictly increasing grid positions.
    w_max : ndarray, shape (n,)
        Upper bounds on ``w`` (finite, >= 0).
    accel, decel : ndarray, shape (n-1,)
        Bounds ``A_i``, ``D_i`` on ``±(w_{i+1} - w_i) / h_i`` (finite, > 0).
    jerk : ndarray, shape (n-2,)
        Bounds ``J_i`` on ``|w''_i| sqrt(w_i)``; ``inf`` drops the row.
    w_start, w_end : float
        Fixed boundary values of ``w``.
    w_min : ndarray, shape (n,), optional
        Lower bounds on ``w`` (e.g. a jerk-limited vehicle leaving a moving state cannot
        slow down faster than its envelope). Lower bounds can make the relaxation inexact
        (the paper's Section 5.1); the refinement then applies.
    lateral : StencilRows or tuple of StencilRows, optional
        Lateral-jerk rows, relaxed like the jerk rows and part of the exactness test; several
        families when a node needs more than one row (the one-sided curvature rates at a join
        of path pieces).
    grip : ndarray, shape (n,), optional
        Friction-ellipse rows: with ``g_i`` the lateral acceleration per unit ``w`` at node
        ``i`` as a fraction of its limit (``|κ_i| / a_lat_max``) and ``u_i`` cell ``i``'s
        acceleration as a fraction of its limit, ``max((w_{i+1} - w_i) / (h_i A_i),
        (w_i - w_{i+1}) / (h_i D_i))``, both ends of every cell hold
        ``u_i² + (g w)² <= 1`` — a second-order cone in ``w``, convex: the relaxation keeps
        its certificate.
    """

    s: FloatArray
    w_max: FloatArray
    accel: FloatArray
    decel: FloatArray
    jerk: FloatArray
    w_start: float = 0.0
    w_end: float = 0.0
    w_min: FloatArray | None = None
    lateral: StencilRows | tuple[StencilRows, ...] | None = None
    grip: FloatArray | None = None

    @property
    def n(self) -> int:
        """Number of grid nodes."""
        return int(self.s.shape[0])

    # h, tau and the second-difference weights are computed on access, not cached: a
    # cached copy on the problem and on its scaled copy stayed alive through every solve
    # (56 bytes per node at the banded kernel's peak), and each costs microseconds.
    @property
    def h(self) -> FloatArray:
        """Steps ``h_i = s_{i+1} - s_i``, shape (n-1,)."""
        s = self.s
        out: FloatArray = s[1:] - s[:-1]  # np.diff, without its overhead
        return out

    @property
    def tau(self) -> FloatArray:
        """Interior cell lengths ``(h_{i-1} + h_i) / 2``, shape (n-2,)."""
        h = self.h
        return 0.5 * (h[:-1] + h[1:])

    @cached_property
    def uniform(self) -> bool:
        """Whether the grid is uniform (to rounding)."""
        h = self.h
        return bool(np.ptp(h) <= 1e-9 * h.mean())

    @cached_property
    def has_lower_bounds(self) -> bool:
        """Whether some interior node has a positive lower bound."""
        return self.w_min is not None and bool((self.w_min[1:-1] > 0).any())

    @cached_property
    def has_jerk(self) -> bool:
        """Whether any jerk row (or lateral-jerk row) is finite."""
        return bool(np.isfinite(self.jerk).any()) or self.has_lateral

    @cached_property
    def has_lateral(self) -> bool:
        """Whether any lateral-jerk row is finite."""
        return any(bool(np.isfinite(f.bound).any()) for f in self.lateral_families)

    @property
    def has_grip(self) -> bool:
        """Whether the problem has friction-ellipse rows ([`grip`][speedplan.DiscreteProblem])."""
        return self.grip is not None

    def grip_load(self, w: FloatArray) -> FloatArray:
        """Per cell, the larger of ``sqrt(u² + (g w)²)`` at its two ends (1 at the ellipse).

        Examples
        --------
        >>> import numpy as np
        >>> p = DiscreteProblem(s=np.array([0.0, 1.0]), w_max=np.ones(2), accel=np.array([2.0]),
        ...                     decel=np.array([2.0]), jerk=np.zeros(0),
        ...                     grip=np.array([0.0, 1.0]))
        >>> p.grip_load(np.array([0.0, 0.6]))  # u = 0.3, g w = 0.6 at the cell's end
        array([0.67082039])
        """
        if self.grip is None:
            return np.zeros(self.n - 1)
        dw = np.diff(w)
        u = np.maximum(dw / (self.h * self.accel), -dw / (self.h * self.decel))
        lat = self.grip * np.maximum(w, 0.0)
        out: FloatArray = np.hypot(u, np.maximum(lat[:-1], lat[1:]))
        return out

    def grip_violation(self, w: FloatArray) -> float:
        """Largest excess of the friction-ellipse rows over 1 (0 without them)."""
        if self.grip is None or self.n < 2:
            return 0.0
        return max(float(np.max(self.grip_load(w))) - 1.0, 0.0)

    @property
    def lateral_families(self) -> tuple[StencilRows, ...]:
        """The lateral-jerk row families (empty without)."""
        if self.lateral is None:
            return ()
        return (self.lateral,) if isinstance(self.lateral, StencilRows) else tuple(self.lateral)

    @property
    def second_difference_weights(self) -> FloatArray:
        """Weights ``(n-2, 3)`` of ``w_{i-1}, w_i, w_{i+1}`` in ``w''_i`` (non-uniform grid)."""
        h = self.h
        h0, h1 = h[:-1], h[1:]
        return np.column_stack(
            (2.0 / (h0 * (h0 + h1)), -2.0 / (h0 * h1), 2.0 / (h1 * (h0 + h1)))
        )

    def stencil_families(self) -> list[StencilRows]:
        """Every row family of the jerk rows' structure: the jerk rows, then lateral jerk."""
        out = [StencilRows(coef=self.second_difference_weights, bound=self.jerk)]
        out.extend(self.lateral_families)
        return out

    @cached_property
    def second_difference(self) -> sp.csr_matrix:
        """Sparse (n-2, n) operator mapping ``w`` to ``w''`` at interior nodes."""
        return self.stencil_matrix(self.second_difference_weights)

    def stencil_matrix(self, coef: FloatArray) -> sp.csr_matrix:
        """Sparse (n-2, n) operator of the three-point stencils ``coef`` at interior nodes."""
        import scipy.sparse as sp  # on first use: import speedplan stays light

        m = self.n - 2
        rows = np.repeat(np.arange(m), 3)
        cols = (np.arange(m)[:, None] + np.arange(3)[None, :]).ravel()
        return sp.csr_matrix((np.asarray(coef).ravel(), (rows, cols)), shape=(m, self.n))

    @staticmethod
    def stencil_apply(coef: FloatArray, w: FloatArray) -> FloatArray:
        """``stencil_matrix(coef) @ w`` without building the matrix: ``c_i · w_{i-1:i+2}``.

        Summed left to right from the first stencil point, as the sparse product does, so the
        two agree to the last bit.

        Examples
        --------
        >>> import numpy as np
        >>> DiscreteProblem.stencil_apply(np.array([[1.0, -2.0, 1.0]]), np.array([1.0, 4.0, 9.0]))
        array([2.])
        """
        c = np.asarray(coef)
        out: FloatArray = c[:, 0] * w[:-2] + c[:, 1] * w[1:-1] + c[:, 2] * w[2:]
        return out

    @staticmethod
    def stencil_adjoint(coef: FloatArray, x: FloatArray) -> FloatArray:
        """``stencil_matrix(coef).T @ x`` without building the matrix (shape ``(n,)``).

        Each node collects the rows it appears in in row order, as the sparse product does.

        Examples
        --------
        >>> import numpy as np
        >>> DiscreteProblem.stencil_adjoint(np.array([[1.0, -2.0, 1.0]]), np.array([3.0]))
        array([ 3., -6.,  3.])
        """
        c = np.asarray(coef)
        out = np.zeros(c.shape[0] + 2)
        out[2:] += c[:, 2] * x
        out[1:-1] += c[:, 1] * x
        out[:-2] += c[:, 0] * x
        return out

    def travel_time(self, w: FloatArray) -> float:
        """The objective ``Σ τ_i / sqrt(w_i)`` over interior nodes (inf if some ``w_i <= 0``)."""
        wi = w[1:-1]
        if (wi <= 0).any():
            return float("inf")
        return float(np.sum(self.tau / np.sqrt(wi)))

    def jerk_rows(self, w: FloatArray) -> FloatArray:
        """Per interior node, ``τ² (|w''| - J / sqrt(w))``: the paper's violation measure.

        On a uniform grid this is ``|w_{i-1} - 2 w_i + w_{i+1}| - h² J_i / sqrt(w_i)``, which is
        invariant under the paper's scaling ``(h, A, J) -> (ρh, A/ρ, J/ρ²)``. Rows with
        ``J = inf`` give ``-inf``.
        """
        return self._rows(self.stencil_apply(self.second_difference_weights, w), self.jerk, w)

    def lateral_rows(self, w: FloatArray) -> FloatArray:
        """Per interior node, the same measure for the lateral-jerk rows (``-inf`` without)."""
        out = np.full(self.n - 2, -np.inf)
        for family in self.lateral_families:
            out = np.maximum(out, self._rows(self.stencil_apply(family.coef, w),
                                             family.bound, w))
        return out

    def relative_row_excess(self, w: FloatArray) -> float:
        """Largest excess of a jerk or lateral-jerk row over its own bound, as a fraction of it.

        ``|load| sqrt(w_i) / bound - 1`` over the rows with a finite positive bound, and 0 when
        every row holds. Unlike `jerk_violation` it does not shrink with the grid's step.
        """
        if not self.has_jerk or self.n < 3:
            return 0.0
        wi = np.sqrt(np.maximum(w[1:-1], 0.0))
        worst = -np.inf
        families = [(self.stencil_apply(self.second_difference_weights, w), self.jerk)]
        families += [(self.stencil_apply(f.coef, w), f.bound) for f in self.lateral_families]
        for load, bound in families:
            held = np.isfinite(bound) & (bound > 0)
            if held.any():
                worst = max(worst, float(np.max(np.abs(load[held]) * wi[held] / bound[held])))
        return max(worst - 1.0, 0.0) if np.isfinite(worst) else 0.0

    def _rows(self, load: FloatArray, bound: FloatArray, w: FloatArray) -> FloatArray:
        wi = np.maximum(w[1:-1], 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            cap = np.where(np.isfinite(bound), bound / np.sqrt(wi), np.inf)
        cap = np.where(np.isnan(cap), np.inf, cap)
        out = np.asarray(self.tau**2 * (np.abs(load) - cap), dtype=np.float64)
        return out

    @cached_property
    def jerk_tol(self) -> float:
        """Exactness threshold on `jerk_violation`: ``1e-7 × max(w_max)``."""
        return JERK_TOL_REL * max(float(np.max(self.w_max)), self.w_start, self.w_end)

    def jerk_violation(self, w: FloatArray) -> float:
        """Largest jerk-row violation (``<= 0`` means every jerk row holds)."""
        if not self.has_jerk or self.n < 3:
            return 0.0
        worst = float(np.max(self.jerk_rows(w)))
        if self.has_lateral:
            worst = max(worst, float(np.max(self.lateral_rows(w))))
        return max(worst, 0.0)

    def linear_violation(self, w: FloatArray) -> float:
        """Largest violation of the linear rows (acceleration, bounds, boundary), in ``w`` units."""
        dw = np.diff(w)
        parts = (
            np.max(dw - self.accel * self.h, initial=0.0),
            np.max(-dw - self.decel * self.h, initial=0.0),
            np.max(w - self.w_max, initial=0.0),
            np.max(-w, initial=0.0),
            np.max(self.w_min - w, initial=0.0) if self.w_min is not None else 0.0,
            abs(w[0] - self.w_start),
            abs(w[-1] - self.w_end),
        )
        return float(max(parts))

    def satisfies_a_priori_exactness(self) -> bool:
        """Corollary 1: constant bounds on a uniform grid and ``w_max`` meets every positive row.

        When true the relaxation is exact whatever its solution (the paper proves it for
        constant ``A`` and ``J``; we also require a uniform grid).
        """
        if not self.has_jerk or self.n < 3:
            return True
        if self.has_lower_bounds or self.has_lateral:
            return False  # the corollary assumes neither (paper, Section 5.1)
        constant = (
            self.uniform
            and np.ptp(self.accel) == 0
            and np.ptp(self.decel) == 0
            and np.all(np.isfinite(self.jerk))
            and np.ptp(self.jerk) == 0
        )
        if not constant:
            return False
        wm = self.w_max.copy()
        wm[0], wm[-1] = self.w_start, self.w_end
        wpp = self.stencil_apply(self.second_difference_weights, wm)
        wi = wm[1:-1]
        with np.errstate(divide="ignore"):
            positive_rows = self.tau**2 * (wpp - self.jerk / np.sqrt(wi))
        return bool(np.all(positive_rows <= self.jerk_tol))

    def scaled(self, s_scale: float, w_scale: float) -> DiscreteProblem:
        """The same problem in units ``s/s_scale`` and ``w/w_scale``.

        ``w`` solves this one iff ``w * w_scale`` solves the original, and travel times differ
        by the factor ``s_scale / sqrt(w_scale)``.
        """
        a_scale = w_scale / s_scale
        j_scale = w_scale**1.5 / s_scale**2
        return DiscreteProblem(
            s=(self.s - self.s[0]) / s_scale,
            w_max=self.w_max / w_scale,
            accel=self.accel / a_scale,
            decel=self.decel / a_scale,
            jerk=self.jerk / j_scale,
            w_start=self.w_start / w_scale,
            w_end=self.w_end / w_scale,
            w_min=None if self.w_min is None else self.w_min / w_scale,
            lateral=tuple(f.scaled(s_scale, w_scale) for f in self.lateral_families) or None,
            grip=None if self.grip is None else self.grip * w_scale,
        )


#: Longest jerk-limited change of acceleration, in grid steps, that the relaxation resolves.
#: The reduced Newton matrix carries the fourth difference ``D̂'D̂`` over such a stretch of
#: active jerk rows, whose condition number grows like its length to the fourth power; in
#: double precision both backends lose the dual equations beyond a few thousand steps
#: (measured on straights with steps of 0.17-2 mm, ``benchmarks/bench_fine_grids.py``: every
#: case up to 4 000 steps solved; from 5 000 on some stalled, a 10 m straight already at
#: 5 000, a 30 m one at 8 000; docs/banded-ipm.md). The grid is refused above this count.
MAX_RAMP_STEPS = 4000


def ramp_steps(problem: DiscreteProblem) -> float:
    """Most grid steps a jerk-limited change of ``w'`` by its bound can take, over all nodes.

    Node ``i``'s jerk row lets ``w'`` change by at most ``r_i = J_i τ_i / sqrt(w_i)`` per
    step (``|w''| sqrt(w) <= J``), fewest at the fastest feasible ``w``. From node ``i`` on,
    count the steps until the ``r`` add up to ``max(A, D)`` there; a node without a jerk row
    ends the count. Invariant under [`DiscreteProblem.scaled`][speedplan.DiscreteProblem].
    """
    finite = np.isfinite(problem.jerk)
    if problem.n < 3 or not finite.any():
        return 0.0
    bound = problem.w_max.copy()  # the fastest feasible w without jerk rows (solve.nojerk)
    bound[0], bound[-1] = min(bound[0], problem.w_start), min(bound[-1], problem.w_end)
    fastest = largest_under_rates(bound, problem.accel * problem.h, problem.decel * problem.h)
    w = np.maximum(fastest[1:-1], 1e-300)
    a = np.maximum.reduce([problem.accel[:-1], problem.accel[1:], problem.decel[:-1],
                           problem.decel[1:]])
    rate = np.where(finite, problem.jerk * problem.tau / np.sqrt(w), np.inf)
    reached = np.concatenate(([0.0], np.cumsum(rate)))
    end = np.searchsorted(reached, reached[:-1] + a, side="left")
    return float(np.max(end - np.arange(rate.size)))

"""Valid linear cuts of the stencil rows over the speed bounds: a tighter lower bound.

The relaxation keeps a stencil row ``|c_i · w| sqrt(w_i) <= B_i`` (a jerk or lateral-jerk row)
only through its epigraph variable, ``t_i >= τ_i |c_i · w| / B_i``: a node may exceed the row
if it pays for it in time. Where exceeding a row for a stretch costs less than slowing down
for it (a curvature that grows fast after a knot of a NURBS, a valley of the yaw-rate bound),
the relaxation's lower bound falls well below the optimum (3.1 % on ``paths/nurbs_edge.json``
with comfort limits).

Every feasible ``w`` meets, at each interior node ``i`` and for either sign,

    L_i = ±c_i · w  <=  f_i(w_i) = min(B_i / sqrt(w_i), M_i + σ_i w_i),

``M_i + σ_i w_i`` being the largest ``L_i`` the acceleration rows allow at that ``w_i``
(``σ_i = ±(c_0 + c_1 + c_2)``, ``M_i`` the largest of ``±(c_2 Δ⁺ - c_0 Δ⁻)`` over the
steps' bounds). On ``lo_i <= w_i <= w_max_i`` the set ``L <= f(w)`` is not convex (``B /
sqrt(w)`` is convex), but every point of it lies under the line through ``(w_max, f(w_max))``
that is tangent to its concave envelope there: a linear row in ``w_{i-1}, w_i, w_{i+1}`` that
removes no feasible point of the discrete problem, and that at ``w_i = w_max_i`` is the row
itself. `secant_cuts` computes these lines exactly (``f`` is linear or convex between its
breakpoints ``lo`` and the crossings of its two terms, so the tangent's slope is the least
secant slope from ``w_max`` to those points); `speedplan.solve.clarabel_` solves the
relaxation with them added.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.checks import FloatArray, IntArray
from .problem import DiscreteProblem, StencilRows

__all__ = ["CUT_MARGIN", "NEWTON_STEPS", "SecantCuts", "secant_cuts"]

#: Newton steps for the crossings of ``B / sqrt(w)`` and ``M + σ w`` (monotone from a
#: bracketing start; converged to rounding well within this).
NEWTON_STEPS = 60
#: Relative margin added to every cut's right-hand side, so that rounding in the crossings
#: never cuts a feasible point.
CUT_MARGIN = 1e-9


@dataclass(frozen=True)
class SecantCuts:
    """Linear rows ``coef_k · (w_{i-1}, w_i, w_{i+1}) <= rhs_k`` at interior nodes ``i = node_k``.

    Attributes
    ----------
    node : ndarray of int, shape (k,)
        Interior node of each row (``1 .. n-2``).
    coef : ndarray, shape (k, 3)
        Weights of ``w_{i-1}, w_i, w_{i+1}``.
    rhs : ndarray, shape (k,)
        Right-hand sides.
    """

    node: IntArray
    coef: FloatArray
    rhs: FloatArray

    @property
    def size(self) -> int:
        """Number of rows."""
        return int(self.node.size)

    def near(self, nodes: IntArray, pad: int) -> SecantCuts:
        """The rows at ``nodes`` and up to ``pad`` nodes on either side of one."""
        if self.size == 0 or nodes.size == 0:
            return SecantCuts(self.node[:0], self.coef[:0], self.rhs[:0])
        top = int(max(self.node.max(), nodes.max())) + pad + 2
        mark = np.zeros(top, dtype=np.intp)
        np.add.at(mark, np.clip(nodes - pad, 0, top - 1), 1)
        np.add.at(mark, np.clip(nodes + pad + 1, 0, top - 1), -1)
        keep = np.cumsum(mark)[self.node] > 0
        return SecantCuts(self.node[keep], self.coef[keep], self.rhs[keep])

    def violation(self, w: FloatArray) -> float:
        """Largest excess of a row at ``w`` (0 when every row holds)."""
        if self.size == 0:
            return 0.0
        i = self.node
        load = self.coef[:, 0] * w[i - 1] + self.coef[:, 1] * w[i] + self.coef[:, 2] * w[i + 1]
        return max(float(np.max(load - self.rhs)), 0.0)


def secant_cuts(problem: DiscreteProblem) -> SecantCuts:
    """The cut of every finite stencil row of ``problem``, for both signs (module notes).

    Rows whose cut the acceleration rows already imply (``f(w_max)`` on its linear term) are
    left out.

    Examples
    --------
    >>> import numpy as np
    >>> p = DiscreteProblem(s=np.linspace(0.0, 4.0, 5), w_max=np.array([0, 4, 1, 4, 0.0]),
    ...                     accel=np.full(4, 2.0), decel=np.full(4, 2.0), jerk=np.full(3, 0.5))
    >>> cuts = secant_cuts(p)
    >>> sorted(set(cuts.node.tolist()))
    [1, 2, 3]
    >>> bool(cuts.violation(np.array([0, 4, 1, 4, 0.0])) > 0)  # the V at node 2 is cut
    True
    >>> bool(cuts.violation(np.array([0, 0.3, 0.4, 0.3, 0.0])) == 0)  # a gentle profile is not
    True
    """
    lo = np.zeros(problem.n) if problem.w_min is None else np.asarray(problem.w_min)
    nodes, coefs, rhss = [], [], []
    for family in problem.stencil_families():
        for sign in (1.0, -1.0):
            got = _family_cuts(problem, family, sign, lo)
            if got is not None:
                nodes.append(got[0])
                coefs.append(got[1])
                rhss.append(got[2])
    if not nodes:
        return SecantCuts(np.zeros(0, dtype=np.intp), np.zeros((0, 3)), np.zeros(0))
    return SecantCuts(np.concatenate(nodes), np.concatenate(coefs), np.concatenate(rhss))


def _family_cuts(problem: DiscreteProblem, family: StencilRows, sign: float, lo: FloatArray
                 ) -> tuple[IntArray, FloatArray, FloatArray] | None:
    """The cuts of one family's rows ``sign · c · w <= f(w_i)``; ``None`` if none."""
    coef = sign * np.asarray(family.coef, dtype=np.float64)
    bound = np.asarray(family.bound, dtype=np.float64)
    c0, c1, c2 = coef[:, 0], coef[:, 1], coef[:, 2]
    h = problem.h
    # Largest c2 Δ⁺ - c0 Δ⁻ over Δ⁺ = w_{i+1} - w_i in [-D h, A h] (cell i) and
    # Δ⁻ = w_i - w_{i-1} in [-D h, A h] (cell i - 1).
    up = np.maximum(c2 * problem.accel[1:] * h[1:], -c2 * problem.decel[1:] * h[1:])
    down = np.maximum(-c0 * problem.accel[:-1] * h[:-1], c0 * problem.decel[:-1] * h[:-1])
    big, sigma = up + down, c0 + c1 + c2
    top, low = problem.w_max[1:-1], np.minimum(lo[1:-1], problem.w_max[1:-1])
    on = np.isfinite(bound) & (top > low) & (top > 0)
    if not on.any():
        return None
    node = np.flatnonzero(on)
    b, m, sg, u, w_lo = bound[on], big[on], sigma[on], top[on], low[on]
    f_top = _envelope_value(b, m, sg, u)
    # The line is implied by the acceleration rows where f(w_max) is on its linear term.
    tight = b / np.sqrt(u) < m + sg * u
    if not tight.any():
        return None
    slope = np.full(u.size, np.inf)
    for p in (w_lo, *_crossings(b, m, sg)):
        ok = np.isfinite(p) & (p >= w_lo) & (p < u)
        q = np.where(ok, p, 0.5 * u)
        secant = (f_top - _envelope_value(b, m, sg, q)) / (u - q)
        slope = np.where(ok, np.minimum(slope, secant), slope)
    keep = tight & np.isfinite(slope)
    i = node[keep] + 1
    s_k, f_k, u_k = slope[keep], f_top[keep], u[keep]
    rows = np.column_stack((c0[node[keep]], c1[node[keep]] - s_k, c2[node[keep]]))
    rhs = f_k - s_k * u_k
    rhs = rhs + CUT_MARGIN * (np.abs(rhs) + np.abs(s_k) * u_k + np.abs(rows).sum(axis=1) * u_k)
    return i, rows, rhs


def _envelope_value(b: FloatArray, m: FloatArray, sigma: FloatArray, w: FloatArray
                    ) -> FloatArray:
    """``f(w) = min(b / sqrt(w), m + σ w)`` (``m + σ w`` at ``w = 0``)."""
    with np.errstate(divide="ignore"):
        g = np.where(w > 0, b / np.sqrt(np.maximum(w, 1e-300)), np.inf)
    out: FloatArray = np.minimum(g, m + sigma * w)
    return out


def _crossings(b: FloatArray, m: FloatArray, sigma: FloatArray
               ) -> tuple[FloatArray, FloatArray]:
    """The ``w > 0`` where ``b / sqrt(w) = m + σ w`` (at most two; NaN where none).

    With ``x = sqrt(w)``: roots of ``F(x) = σ x³ + m x - b``. For ``σ >= 0`` ``F`` is convex
    and increasing: one root, reached by Newton from an upper bound. For ``σ < 0`` ``F`` is
    concave with its maximum at ``x_m = sqrt(m / (-3 σ))``: two roots if ``F(x_m) >= 0``, reached
    by Newton from 0 and from an upper bound, monotonically (the tangent of a concave function
    lies above it).
    """
    neg = sigma < 0
    pos_s = np.where(neg, 0.0, sigma)
    with np.errstate(divide="ignore", invalid="ignore"):
        # sigma >= 0: start right of the root, x0 >= cbrt(b / σ) and >= b / m.
        x = np.maximum(np.where(pos_s > 0, np.cbrt(b / np.where(pos_s > 0, pos_s, 1.0)), 0.0),
                       np.where(m > 0, b / np.where(m > 0, m, 1.0), 0.0))
        x = np.where(x > 0, x, np.inf)
        xm = np.where(neg, np.sqrt(np.maximum(m, 0.0) / np.where(neg, -3.0 * sigma, 1.0)), 0.0)
        peak = sigma * xm**3 + m * xm - b
        two = neg & (peak >= 0.0)
        left = np.zeros_like(b)  # from 0 towards the first root
        right = np.where(two, np.maximum(2.0 * xm, np.sqrt(np.maximum(m, 0.0)
                                                           / np.where(neg, -sigma, 1.0))), 0.0)
        for _ in range(NEWTON_STEPS):
            x = _newton(x, sigma, m, b)
            left = _newton(left, sigma, m, b)
            right = _newton(right, sigma, m, b)
    first = np.where(neg, np.where(two, left, np.nan), np.where(np.isfinite(x), x, np.nan))
    second = np.where(two, right, np.nan)
    return first**2, second**2


def _newton(x: FloatArray, sigma: FloatArray, m: FloatArray, b: FloatArray) -> FloatArray:
    f = sigma * x**3 + m * x - b
    d = 3.0 * sigma * x**2 + m
    step = np.where(np.isfinite(x) & (d != 0), f / np.where(d != 0, d, 1.0), 0.0)
    out: FloatArray = np.where(np.isfinite(x), x - step, x)
    return out

"""Exact O(n) solution of the problem without jerk rows: a forward and a backward pass.

Without jerk rows the pointwise largest feasible ``w`` is optimal, because the objective
decreases in every ``w_i``: the largest sequence under ``w_max`` whose rises are at most
``A_i h_i`` and falls at most ``D_i h_i`` (`speedplan.core.rates`).
"""

from __future__ import annotations

import numpy as np

from ..core.checks import FloatArray
from ..core.errors import InfeasibleError
from ..core.rates import cumulative, largest_under_rates
from .problem import DiscreteProblem

__all__ = ["check_reachable", "max_feasible_w", "min_feasible_w", "positive_feasible_w"]


def max_feasible_w(problem: DiscreteProblem, *, pin_ends: bool = True) -> FloatArray:
    """Largest ``w`` meeting the bounds and the acceleration/braking rows.

    With ``pin_ends`` the end values are capped at ``w_start`` and ``w_end``; the result then
    equals them exactly when the boundary values are reachable (see `check_reachable`).

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.solve.problem import DiscreteProblem
    >>> p = DiscreteProblem(s=np.arange(5.0), w_max=np.full(5, 10.0), accel=np.ones(4),
    ...                     decel=np.ones(4), jerk=np.full(3, np.inf))
    >>> max_feasible_w(p).tolist()
    [0.0, 1.0, 2.0, 1.0, 0.0]
    """
    bound = problem.w_max.copy()
    if pin_ends:
        bound[0] = min(bound[0], problem.w_start)
        bound[-1] = min(bound[-1], problem.w_end)
    h = problem.h
    return largest_under_rates(bound, problem.accel * h, problem.decel * h)


def positive_feasible_w(problem: DiscreteProblem) -> FloatArray:
    """`max_feasible_w`; `InfeasibleError` unless it is positive inside.

    With jerk rows the travel time of a ``w`` that vanishes at an interior node is infinite,
    and no solver can find a finite one there: a zero speed bound inside, or bounds and
    acceleration rows that force one. The error's ``s`` is in the problem's own grid
    positions, so call this before scaling the problem (``DiscreteProblem.scaled``).

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.solve.problem import DiscreteProblem
    >>> p = DiscreteProblem(s=np.arange(5.0) * 2.0, w_max=np.array([1.0, 1.0, 0.0, 1.0, 1.0]),
    ...                     accel=np.ones(4), decel=np.ones(4), jerk=np.ones(3))
    >>> try:
    ...     positive_feasible_w(p)
    ... except InfeasibleError as exc:
    ...     print(exc.constraint, exc.s)
    w_max 4.0
    """
    w = max_feasible_w(problem)
    inner = w[1:-1]
    if inner.size and float(np.min(inner)) <= 0.0:
        i = int(np.argmin(inner)) + 1
        raise InfeasibleError(
            f"the relaxation is infeasible: no speed law with w > 0 at s={problem.s[i]:.6g} "
            "meets the speed bound and the acceleration bounds",
            constraint="w_max",
            s=float(problem.s[i]),
        )
    return w


def min_feasible_w(problem: DiscreteProblem) -> FloatArray:
    """Smallest ``w`` meeting the acceleration/braking rows from ``w_start`` and into ``w_end``.

    Braking from ``w_start`` and accelerating into ``w_end`` as hard as allowed, floored at 0
    and at ``w_min`` (the floor may break an acceleration row where ``w_min`` rises faster
    than the acceleration bound). Every ``w`` meeting the rows and the fixed ends lies above
    it; with the speed bounds ignored it is itself feasible when ``w_min`` is not given.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.solve.problem import DiscreteProblem
    >>> p = DiscreteProblem(s=np.arange(5.0), w_max=np.full(5, 10.0), accel=np.ones(4),
    ...                     decel=np.ones(4), jerk=np.full(3, np.inf), w_start=3.0)
    >>> min_feasible_w(p).tolist()
    [3.0, 2.0, 1.0, 0.0, 0.0]
    """
    braking = problem.w_start - cumulative(problem.decel * problem.h)
    accel = cumulative(problem.accel * problem.h)
    accelerating = problem.w_end - (accel[-1] - accel)
    w: FloatArray = np.maximum(np.maximum(braking, accelerating), 0.0)
    if problem.w_min is not None:
        w = np.maximum(w, problem.w_min)
    return w


def check_reachable(problem: DiscreteProblem, *, units: str = "") -> None:
    """Raise `InfeasibleError` if ``w_start`` / ``w_end`` cannot be met.

    The message names the bound that cannot be reached and where (grid position ``s``).
    """
    tol = 1e-9 * max(1.0, float(np.max(problem.w_max)))
    s = problem.s
    for name, value, bound in (
        ("w_start", problem.w_start, problem.w_max[0]),
        ("w_end", problem.w_end, problem.w_max[-1]),
    ):
        if value > bound + tol:
            where = s[0] if name == "w_start" else s[-1]
            raise InfeasibleError(
                f"`{name}`={value:.6g} exceeds the bound w_max={bound:.6g} at s={where:.6g}{units}",
                constraint=name,
                s=float(where),
            )
    # Braking from w_start: the backward pass alone says how fast each node may be.
    c = cumulative(problem.decel * problem.h)  # w_0 <= w_max_j + c_j - c_0
    _check_pass(problem, tol, units, "decel", problem.w_start, c, -1, problem.w_end,
                "cannot brake from w_start={w_start:.6g} down to w_max={w:.6g} at s={s:.6g}"
                "{units} under the braking bound")
    if problem.has_lower_bounds:
        assert problem.w_min is not None
        short = problem.w_min - max_feasible_w(problem)
        if (short > tol).any():
            j = int(np.argmax(short > tol))
            # The bound ahead that the braking from node j cannot reach in time.
            c = cumulative(problem.decel * problem.h)
            k = j + int(np.argmin(problem.w_max[j:] + c[j:]))
            raise InfeasibleError(
                f"cannot slow down in time for the bound w_max={problem.w_max[k]:.6g} at "
                f"s={s[k]:.6g}{units}: the slowest jerk-limited motion still has "
                f"w={problem.w_min[j]:.6g} at s={s[j]:.6g}{units}",
                constraint="jerk",
                s=float(s[k]),
            )
    # Accelerating into w_end: the forward pass, likewise.
    c = cumulative(problem.accel * problem.h)  # w_end <= w_max_j + (c_end - c_j)
    _check_pass(problem, tol, units, "accel", problem.w_end, c[-1] - c, 0, problem.w_start,
                "cannot accelerate from w_max={w:.6g} at s={s:.6g}{units} up to "
                "w_end={w_end:.6g} under the acceleration bound")


def _check_pass(problem: DiscreteProblem, tol: float, units: str, constraint: str,
                value: float, reach: FloatArray, other_end: int, other_value: float,
                message: str) -> None:
    """Raise unless ``value`` at one end is at most ``w_max_j + reach_j`` at every node ``j``.

    ``reach_j`` is what the rate rows allow between node ``j`` and that end; the bound of the
    node ``other_end`` is also the other end's value ``other_value``. ``message`` is formatted
    with the binding node's bound ``w`` and position ``s``, ``units``, ``w_start``, ``w_end``.
    """
    bound = problem.w_max.copy()
    bound[other_end] = min(bound[other_end], other_value)
    limit = bound + reach
    j = int(np.argmin(limit))
    if value > limit[j] + tol:
        raise InfeasibleError(
            message.format(w=bound[j], s=problem.s[j], units=units, w_start=problem.w_start,
                           w_end=problem.w_end),
            constraint=constraint,
            s=float(problem.s[j]),
        )

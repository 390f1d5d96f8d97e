"""The largest sequence under pointwise bounds whose rises and falls per step are bounded.

Chaining ``w_{i+1} <= w_i + up_i`` from every node ``j`` gives ``w_i <= bound_j + c_i - c_j``
with ``c`` the cumulative sum of ``up``, so the forward pass is
``c + minimum.accumulate(bound - c)``; the backward pass (falls at most ``down_i``) is the same
on the reversed sequence. With ``up = A h`` and ``down = D h`` this is the exact optimum of
the discrete problem without jerk rows (`speedplan.solve.nojerk`), and the model's estimate
of how fast a vehicle can go on a grid before it knows the jerk-limited answer.
"""

from __future__ import annotations

import numpy as np

from .checks import FloatArray

__all__ = ["cumulative", "largest_under_rates"]


def cumulative(step: FloatArray) -> FloatArray:
    """``c_i = Σ_{k<i} step_k`` (n values for n - 1 steps): the most ``w_i - w_0`` can gain.

    Examples
    --------
    >>> import numpy as np
    >>> cumulative(np.array([1.0, 2.0, 3.0])).tolist()
    [0.0, 1.0, 3.0, 6.0]
    """
    out: FloatArray = np.empty(step.size + 1)
    out[0] = 0.0
    np.add.accumulate(step, out=out[1:])  # np.cumsum's loop, without its dispatch
    return out


def _forward(bound: FloatArray, up: FloatArray) -> FloatArray:
    c = cumulative(up)
    out: FloatArray = np.subtract(bound, c)
    np.minimum.accumulate(out, out=out)
    out += c
    return np.minimum(out, bound, out=out)


def largest_under_rates(bound: FloatArray, up: FloatArray, down: FloatArray) -> FloatArray:
    """Pointwise largest ``w <= bound`` with rises at most ``up`` and falls at most ``down``.

    That is ``w_{i+1} - w_i <= up_i`` and ``w_i - w_{i+1} <= down_i``; floored at 0 (a bound
    below 0 cannot be met by a squared speed).

    Parameters
    ----------
    bound : ndarray, shape (n,)
        Upper bound at each node.
    up, down : ndarray, shape (n - 1,)
        Largest rise and largest fall over each step.

    Examples
    --------
    >>> import numpy as np
    >>> largest_under_rates(np.array([0.0, 9.0, 9.0, 9.0, 0.0]), np.ones(4), np.ones(4)).tolist()
    [0.0, 1.0, 2.0, 1.0, 0.0]
    """
    w = _forward(bound, up)
    w = _forward(w[::-1], down[::-1])[::-1]
    return np.maximum(w, 0.0)

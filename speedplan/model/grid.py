"""Default arc-length grids: fine where the jerk-limited transitions are short.

A transition between accelerating and cruising takes ``t_j = min(a/j, sqrt(v_max/j))``
seconds; at speed ``v`` it spans ``v t_j`` metres and from rest ``ℓ = j t_j³ / 6``. The default
grid places ``per_phase`` nodes on each such transition, using the speed of the exact no-jerk
optimum as the estimate of ``v(s)``: fine near standstill, coarser at cruise.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..core.checks import FloatArray, grid_size
from ..solve.nojerk import max_feasible_w
from ..solve.problem import DiscreteProblem

__all__ = ["DEFAULT_PER_PHASE", "MAX_DEFAULT_NODES", "adaptive_grid", "uniform_grid"]

#: Nodes per jerk transition of the default grid (measured: jerk within 6 % of j_max on a
#: straight rest-to-rest move; see the convergence table in the docs).
DEFAULT_PER_PHASE = 80
MAX_DEFAULT_NODES = 20_000
MIN_NODES = 200


def uniform_grid(length: float, *, n: int | None = None, ds: float | None = None) -> FloatArray:
    """Uniform grid over ``[0, length]`` with ``n`` nodes or step at most ``ds``."""
    if n is None:
        assert ds is not None
        n = int(np.ceil(length / ds)) + 1
    n = grid_size("n", max(int(n), 3))
    return np.linspace(0.0, length, n)


def adaptive_grid(
    length: float,
    w_bound: Callable[[FloatArray], FloatArray],
    *,
    a_max: float,
    a_decel: float,
    v_max: float,
    j_max: float,
    w_start: float,
    w_end: float,
    per_phase: float = DEFAULT_PER_PHASE,
) -> FloatArray:
    """Non-uniform grid with node density ``per_phase / max(ℓ, v_est(s) t_j)``."""
    a = min(a_max, a_decel)
    t_j = min(a / j_max, np.sqrt(v_max / j_max))
    ell = j_max * t_j**3 / 6.0
    n_pre = int(np.clip(4 * length / max(ell, 1e-12), 2001, 200_001))
    sf = np.linspace(0.0, length, n_pre)
    pre = DiscreteProblem(
        s=sf, w_max=w_bound(sf), accel=np.full(n_pre - 1, 2 * a_max),
        decel=np.full(n_pre - 1, 2 * a_decel), jerk=np.full(n_pre - 2, np.inf),
        w_start=w_start, w_end=w_end,
    )
    v_est = np.sqrt(max_feasible_w(pre, pin_ends=False))
    density = per_phase / np.maximum(ell, v_est * t_j)
    cum = np.concatenate(([0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) * np.diff(sf))))
    n = int(np.clip(np.ceil(cum[-1]) + 1, MIN_NODES, MAX_DEFAULT_NODES))
    grid: FloatArray = np.interp(np.linspace(0.0, cum[-1], n), cum, sf)
    grid[0], grid[-1] = 0.0, length
    return grid

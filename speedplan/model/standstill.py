"""Jerk rows next to a standstill, recalibrated so the exact max-jerk start is feasible."""

from __future__ import annotations

import numpy as np

from ..core.checks import FloatArray
from ..solve.problem import DiscreteProblem
from .boundary import max_jerk_envelope

__all__ = ["STANDSTILL_ROWS", "calibrate_standstill_rows"]

#: Jerk rows recalibrated next to a standstill (see `calibrate_standstill_rows`).
STANDSTILL_ROWS = 8


def calibrate_standstill_rows(jerk: FloatArray, s: FloatArray, v0: float, a0: float,
                              vf: float, af: float, j_max: float) -> None:
    """Make the exact max-jerk start (stop) feasible for the first (last) jerk rows, in place.

    From rest ``w ∝ s^{4/3}`` has ``w''`` singular at ``s = 0``; the three-point second
    difference overestimates it next to the standstill (by 17 % at the first node of a uniform
    grid, whatever the step), which would make the discrete optimum leave standstill later than
    the true one — a delay that shrinks only like ``h^{1/3}``. Scaling those few rows so that the
    max-jerk envelope meets them exactly removes the bias; the time law and ``verify()`` then
    check the realised jerk in continuous time.
    """
    k = min(STANDSTILL_ROWS, jerk.size)
    for at_rest, idx, dist in (
        (v0 == 0.0 and a0 == 0.0, slice(0, k + 2), s[: k + 2] - s[0]),
        (vf == 0.0 and af == 0.0, slice(s.size - k - 2, s.size), s[-1] - s[-k - 2 :]),
    ):
        if not at_rest:
            continue
        env = max_jerk_envelope(dist, j_max)
        sub = DiscreteProblem(s=s[idx], w_max=env, accel=np.ones(k + 1), decel=np.ones(k + 1),
                              jerk=np.full(k, np.inf))
        # The stencil product without a sparse matrix (bitwise the same, a fraction of the time).
        d2 = sub.stencil_apply(sub.second_difference_weights, env)
        load = np.abs(d2) * np.sqrt(env[1:-1]) / (2.0 * j_max)
        rows = slice(0, k) if idx.start == 0 else slice(jerk.size - k, jerk.size)
        jerk[rows] *= np.maximum(1.0, load)

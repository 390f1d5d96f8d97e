"""Jerk-limited envelopes at the ends of a move.

The paper's model leaves the acceleration free at a standstill: ``w`` may grow linearly from
0, i.e. the vehicle jumps to full acceleration. A jerk-limited vehicle starting from
``(v0, a0)`` cannot be faster at any ``s`` than the maximum-jerk motion
``v(t) = v0 + a0 t + j t²/2``, ``s(t) = v0 t + a0 t²/2 + j t³/6``; from rest this is
``w <= (j²/4) (6 s / j)^{4/3}``. Capping ``w_max`` by this envelope (and its mirror image at the
end, with ``a0 -> -af``) makes the discrete optimum converge to the true jerk-limited optimum.
"""

from __future__ import annotations

import numpy as np

from ..core.checks import FloatArray
from ..core.errors import InfeasibleError

__all__ = ["check_boundary_state", "jerk_motion_w", "max_jerk_envelope"]


def check_boundary_state(v: float, a: float, j_max: float, *, end: bool) -> None:
    """Raise :class:`InfeasibleError` if a jerk-limited move cannot leave/reach ``(v, a)``.

    Leaving ``v`` while decelerating at ``a < 0`` stops the vehicle unless ``v >= a²/(2 j)``;
    arriving at ``v`` while accelerating at ``a > 0`` likewise needs ``v >= a²/(2 j)``.
    """
    slowing = -a if not end else a
    if slowing > 0 and np.isfinite(j_max) and v < slowing**2 / (2 * j_max) * (1 - 1e-12):
        which = ("vf", "af") if end else ("v0", "a0")
        raise InfeasibleError(
            f"`{which[0]}`={v:.6g} m/s with `{which[1]}`={a:.6g} m/s² is not reachable under "
            f"j_max={j_max:.6g} m/s³: the speed would pass through zero (needs "
            f"{which[0]} >= {which[1]}²/(2 j_max) = {slowing**2 / (2 * j_max):.6g} m/s)",
            constraint="jerk",
            s=None,
        )


def max_jerk_envelope(d: FloatArray, j_max: float) -> FloatArray:
    """Largest ``w = v²`` at distance ``d >= 0`` from rest (zero speed and acceleration).

    The closed form ``(j²/4) (6 d / j)^{4/3}`` of the maximum-jerk start; moving states use
    :func:`jerk_motion_w`.

    Examples
    --------
    From rest with ``j_max = 0.5``: after 2 s the vehicle has covered ``j t³/6 = 2/3`` m at
    ``v = j t²/2 = 1`` m/s.

    >>> import numpy as np
    >>> w = max_jerk_envelope(np.array([0.0, 2.0 / 3.0]), j_max=0.5)
    >>> np.round(w, 12).tolist()
    [0.0, 1.0]
    """
    d = np.maximum(np.asarray(d, dtype=np.float64), 0.0)
    if not np.isfinite(j_max):
        return np.full(d.shape, np.inf)
    return np.asarray((j_max * j_max / 4.0) * (6.0 * d / j_max) ** (4.0 / 3.0), dtype=np.float64)


def jerk_motion_w(d: FloatArray, v: float, a: float, jerk: float, a_limit: float) -> FloatArray:
    """Squared speed at distance ``d`` along a jerk-then-constant-acceleration motion.

    The motion leaves ``(v, a)`` with constant ``jerk`` until the acceleration reaches
    ``a_limit``, then keeps that acceleration; ``w`` is 0 once the motion has stopped.

    With ``jerk = -j_max``, ``a_limit = -a_decel`` and ``a <= 0`` this is the slowest a
    jerk-limited vehicle leaving ``(v, a)`` can be at each distance: a valid lower bound on
    ``w`` (for ``a > 0`` pass ``min(a, 0)``, which keeps it valid).

    Examples
    --------
    >>> import numpy as np
    >>> jerk_motion_w(np.array([0.0, 100.0]), v=2.0, a=0.0, jerk=-0.5, a_limit=-1.0).tolist()
    [4.0, 0.0]
    """
    d = np.maximum(np.asarray(d, dtype=np.float64), 0.0)
    t1 = max((a_limit - a) / jerk, 0.0)  # end of the jerk phase
    v1 = v + a * t1 + 0.5 * jerk * t1 * t1
    s1 = v * t1 + 0.5 * a * t1 * t1 + jerk * t1**3 / 6.0

    def state(t: FloatArray) -> tuple[FloatArray, FloatArray]:
        tj = np.minimum(t, t1)
        tc = np.maximum(t - t1, 0.0)
        vj = v + a * tj + 0.5 * jerk * tj * tj
        sj = v * tj + 0.5 * a * tj * tj + jerk * tj**3 / 6.0
        in_const = t > t1
        vel = np.where(in_const, v1 + a_limit * tc, vj)
        pos = np.where(in_const, s1 + v1 * tc + 0.5 * a_limit * tc * tc, sj)
        return pos, vel

    # Time until the motion stops (speed reaches 0), or a horizon beyond every d.
    horizon = 1.0
    for _ in range(200):
        pos, vel = state(np.array([horizon]))
        if vel[0] <= 0 or pos[0] >= d.max():
            break
        horizon *= 2.0
    lo, hi = np.zeros_like(d), np.full_like(d, horizon)
    for _ in range(100):  # bisection on t: s(t) increases while v > 0
        mid = 0.5 * (lo + hi)
        pos, vel = state(mid)
        beyond = (pos >= d) | (vel <= 0)
        hi = np.where(beyond, mid, hi)
        lo = np.where(beyond, lo, mid)
    _, vel = state(hi)
    out: FloatArray = np.maximum(vel, 0.0) ** 2
    return np.where(d == 0, v * v, out)

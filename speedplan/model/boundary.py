"""What a jerk-limited vehicle can do from a boundary state: envelopes and reachability.

Along a straight line the motion is 1-D: position ``s``, speed ``v >= 0``, acceleration ``a``
in ``[-a_decel, a_max]``, jerk in ``[-j, j]``. Everything here is a closed form of that
system.

* **Envelopes.** The slowest motion leaving ``(v0, a0)`` applies ``-j`` down to ``-a_decel``;
  no jerk-limited motion is slower at any ``s`` (one that gets to ``s`` earlier has had less
  time to lower its acceleration), so it bounds ``w = v²`` from below — `jerk_motion_w`.
  The largest ``w`` at a distance is *not* the fastest motion in time (``+j`` up to ``a_max``):
  a motion that is slower gets to ``s`` later and may have built up more acceleration by
  then. By Pontryagin's principle the motion that maximises ``v`` at a given distance applies
  ``-j`` then ``+j`` (one switch), and the speed bound ``v >= 0`` makes the extreme either no
  ``-j`` at all or the stop-and-go motion: brake to rest in the shortest distance, then
  ``+j`` from rest. `fastest_w` is the larger of the two; from rest it is
  ``(j²/4)(6 s/j)^{4/3}`` up to ``a_max`` (`max_jerk_envelope`). The same at the end,
  time reversed (``a -> -a``).
* **Reachability.** From ``(v0, a0)`` the speed passes through ``v0 + a0 |a0| / (2 j)`` at
  least (it keeps rising while the acceleration is brought to 0): above ``v_max`` the state
  cannot be met, below 0 it cannot either, and at exactly 0 the vehicle comes to rest on the
  way (`turnaround_speed`). A stop needs at least the distance of the time-optimal
  braking profile (`stop_distance`), a move between two states at least
  `min_distance`. `check_reachable_states` raises
  [`InfeasibleError`][speedplan.InfeasibleError] naming the state and the limit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.checks import FloatArray
from ..core.errors import InfeasibleError

__all__ = [
    "STATE_JERK_LAW_ROUNDING",
    "STATE_JERK_PINNED",
    "STATE_JERK_ROUNDING",
    "STATE_JERK_SLACK",
    "Phase",
    "check_reachable_states",
    "fastest_w",
    "jerk_motion_w",
    "max_jerk_envelope",
    "min_distance",
    "run_phases",
    "state_jerk",
    "stop_distance",
    "transition",
    "turnaround_speed",
]

#: Relative slack of the reachability tests (rounding of the closed forms).
_SLACK = 1e-9
#: Moving boundary states just outside what ``j_max`` reaches are planned with
#: ``j_max (1 + STATE_JERK_SLACK)`` (`speedplan.strategy.model_request`, with a
#: warning).
STATE_JERK_SLACK = 0.02
#: A moving boundary state that ``j_max (1 + STATE_JERK_ROUNDING)`` reaches is planned with
#: that jerk, silently: a state read off a plan lies on the boundary of what
#: ``j_max`` reaches (the time-optimal motion rides its limits) and the law's rounding puts
#: it a hair outside (measured: the U-turn's state at t = 3 s needs 2.6e-5 more jerk).
STATE_JERK_ROUNDING = 1e-4
#: ... and one that ``j_max (1 + STATE_JERK_LAW_ROUNDING)`` reaches, silently too, in the stretch
#: that holds it: a state read off the final jerk phase of a plan's stop, whose law rides
#: ``j_max`` there within its own rounding (measured: up to 2.3e-3 more jerk needed).
STATE_JERK_LAW_ROUNDING = 3e-3
#: A moving state on the edge of what ``j_max`` reaches downstream (its slowest motion, at
#: ``-j_max``, is the only one that meets a cap further on: a state read off a road's plan
#: braking into the lateral-jerk caps of the next clothoid joins) leaves its discrete problem
#: no interior: the refinement finds no feasible point. The leg is solved again on its grid
#: with ``j_max (1 + STATE_JERK_PINNED)`` in its rows (`speedplan.strategy`, attempt
#: ``"state_rounding_on_grid"``, silent; the plan is verified against ``j_max``). Measured on
#: that state: 1e-4 leaves the refinement infeasible, 1e-3 solves it in 0.06 s.
STATE_JERK_PINNED = 1e-3


def state_jerk(j_max: float) -> float:
    """The jerk a plan from a marginal boundary state may use: ``j_max (1 + STATE_JERK_SLACK)``.

    Examples
    --------
    >>> state_jerk(0.5)
    0.51
    """
    return j_max * (1.0 + STATE_JERK_SLACK)


def max_jerk_envelope(d: FloatArray, j_max: float) -> FloatArray:
    """Largest ``w = v²`` at distance ``d >= 0`` from rest (zero speed and acceleration).

    The closed form ``(j²/4) (6 d / j)^{4/3}`` of the maximum-jerk start; moving states use
    `jerk_motion_w`.

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


def _cubic_time(d: FloatArray, v: float, a: float, jerk: float, t_end: float) -> FloatArray:
    """Smallest ``t`` in ``[0, t_end]`` with ``v t + a t²/2 + jerk t³/6 = d`` (s increasing).

    Cardano's formula for every root, the one in the bracket kept, then two Newton steps
    inside the bracket (the closed form loses digits when the cubic term is small or the
    roots are close). From rest (``v = a = 0``, every standstill of a rest-to-rest move)
    the root is ``cbrt(6 d / jerk)`` itself: a twentieth of the cost on the grids' 200 000
    point pre-grids, and the same to 1e-17 s.
    """
    if v == 0.0 and a == 0.0 and jerk > 0.0:
        rest: FloatArray = np.clip(np.cbrt(6.0 * d / jerk), 0.0, t_end)
        return rest
    # t³ + b t² + c t + e = 0 with b = 3a/J, c = 6v/J, e = -6d/J.
    b, c = 3.0 * a / jerk, 6.0 * v / jerk
    e = -6.0 * d / jerk
    p = c - b * b / 3.0
    q = 2.0 * b**3 / 27.0 - b * c / 3.0 + e
    shift = -b / 3.0
    disc = (q / 2.0) ** 2 + (p / 3.0) ** 3
    # One real root where disc >= 0 (Cardano), three where disc < 0 (trigonometric form):
    # each formula evaluated only on its own entries.
    cand = np.full((4, *disc.shape), np.nan)
    one = disc >= 0
    if one.any():
        qo, sq = q[one], np.sqrt(disc[one])
        cand[0][one] = np.cbrt(-qo / 2.0 + sq) + np.cbrt(-qo / 2.0 - sq) + shift
    three = ~one
    if three.any():
        qt = q[three]
        with np.errstate(invalid="ignore", divide="ignore"):
            r = np.sqrt(np.maximum(-p / 3.0, 0.0))
            arg = np.clip(np.where(r > 0, (-qt / 2.0) / np.where(r > 0, r**3, 1.0), 0.0),
                          -1.0, 1.0)
            phi = np.arccos(arg) / 3.0
            for k in range(3):
                cand[k + 1][three] = 2.0 * r * np.cos(phi - 2.0 * np.pi * k / 3.0) + shift
    ok = np.isfinite(cand) & (cand >= -1e-12 * max(t_end, 1.0)) & (cand <= t_end * (1 + 1e-12))
    t = np.where(ok, cand, np.inf).min(axis=0)
    # Fall back to the bracket's midpoint if rounding lost every root; Newton fixes it.
    t = np.where(np.isfinite(t), t, 0.5 * t_end)
    t = np.clip(t, 0.0, t_end)
    for _ in range(3):
        f = v * t + 0.5 * a * t * t + jerk * t**3 / 6.0 - d
        df = v + a * t + 0.5 * jerk * t * t
        with np.errstate(divide="ignore", invalid="ignore"):
            step = np.where(df > 0, f / df, 0.0)
        t = np.clip(t - step, 0.0, t_end)
    out: FloatArray = t
    return out


def jerk_motion_w(d: FloatArray, v: float, a: float, jerk: float, a_limit: float) -> FloatArray:
    """Squared speed at distance ``d`` along a jerk-then-constant-acceleration motion.

    The motion leaves ``(v, a)`` with constant ``jerk`` until the acceleration reaches
    ``a_limit``, then keeps that acceleration; ``w`` is 0 once the motion has stopped.
    Closed form: the jerk phase is a cubic in time (`_cubic_time`), the constant
    acceleration phase is linear in ``w``.

    With ``jerk = +j_max`` and ``a_limit = a_max`` it is the fastest motion leaving ``(v, a)``;
    with ``jerk = -j_max`` and ``a_limit = -a_decel`` the slowest (a lower bound on ``w``
    until it stops).

    Examples
    --------
    >>> import numpy as np
    >>> jerk_motion_w(np.array([0.0, 100.0]), v=2.0, a=0.0, jerk=-0.5, a_limit=-1.0).tolist()
    [4.0, 0.0]
    >>> w = jerk_motion_w(np.array([2.0 / 3.0]), v=0.0, a=0.0, jerk=0.5, a_limit=1.0)
    >>> round(float(w[0]), 12)  # after 2 s from rest: v = 1 m/s
    1.0
    """
    d = np.maximum(np.asarray(d, dtype=np.float64), 0.0)
    t1 = max((a_limit - a) / jerk, 0.0)  # end of the jerk phase
    # The motion stops during the jerk phase if v(t) = v + a t + jerk t²/2 reaches 0 first.
    t_stop = _first_stop(v, a, jerk, t1)
    t_jerk = min(t1, t_stop)
    s_jerk = v * t_jerk + 0.5 * a * t_jerk**2 + jerk * t_jerk**3 / 6.0
    v1 = v + a * t_jerk + 0.5 * jerk * t_jerk**2
    in_jerk = d <= s_jerk
    t = _cubic_time(np.where(in_jerk, d, 0.0), v, a, jerk, t_jerk)
    vj = np.maximum(v + a * t + 0.5 * jerk * t * t, 0.0)
    if t_stop < t1 or (t_jerk == 0.0 and v1 <= 0.0):  # stopped within the jerk phase
        w_after = np.zeros_like(d)
    else:
        w_after = np.maximum(v1 * v1 + 2.0 * a_limit * (d - s_jerk), 0.0)
    out: FloatArray = np.where(in_jerk, vj * vj, w_after)
    return np.where(d == 0, v * v, out)


def fastest_w(d: FloatArray, v: float, a: float, j_max: float, a_limit: float,
              a_brake: float) -> FloatArray:
    """Largest ``w = v²`` a jerk-limited motion leaving ``(v, a)`` can have at distance ``d``.

    The upper envelope in distance: the larger of the maximum-jerk motion
    (`jerk_motion_w` with ``+j_max`` up to ``a_limit``) and the stop-and-go motion,
    which brakes to rest in the shortest distance (`stop_distance`, deceleration up to
    ``a_brake``) and then starts again with ``+j_max``. The second is larger far enough
    away: having come to rest it covers the distance later, with more acceleration built up.
    See the module docstring for why no other motion is faster at ``d``.

    Examples
    --------
    From 0.3 m/s braking at 0.2 m/s² (``j = 0.1``), 2 m on, the motion that first comes to
    rest is faster than the one that raises its acceleration at once:

    >>> import numpy as np
    >>> d = np.array([2.0])
    >>> fast_in_time = jerk_motion_w(d, 0.3, -0.2, 0.1, 1.0)
    >>> bool(fastest_w(d, 0.3, -0.2, 0.1, 1.0, 1.0)[0] > fast_in_time[0])
    True
    """
    d = np.maximum(np.asarray(d, dtype=np.float64), 0.0)
    w = jerk_motion_w(d, v, a, j_max, a_limit)
    if v <= 0.0 or not np.isfinite(j_max):
        return w
    braking = stop_distance(v, a, j_max, a_brake)
    restart = jerk_motion_w(d - braking, 0.0, 0.0, j_max, a_limit)
    out: FloatArray = np.where(d > braking, np.maximum(w, restart), w)
    return out


def _first_stop(v: float, a: float, jerk: float, t_max: float) -> float:
    """First time in ``[0, t_max]`` where ``v + a t + jerk t²/2`` reaches 0 (``inf``: never)."""
    if v <= 0.0:  # at rest: it moves off only if its acceleration is (or turns) positive
        return np.inf if a > 0.0 or (a == 0.0 and jerk > 0.0) else 0.0
    # Roots of (jerk/2) t² + a t + v = 0, computed without cancellation.
    disc = a * a - 2.0 * jerk * v
    if disc < 0.0:
        return np.inf
    sq = np.sqrt(disc)
    qq = -0.5 * (a + np.copysign(sq, a))
    roots = [r for r in ((qq / (0.5 * jerk)) if jerk != 0 else np.inf,
                         (v / qq) if qq != 0 else np.inf) if np.isfinite(r) and r >= 0.0]
    first = min(roots) if roots else np.inf
    return float(first) if first <= t_max else np.inf


def turnaround_speed(v: float, a: float, j_max: float) -> float:
    """Speed at which the acceleration ``a`` is first brought to 0: ``v + a |a| / (2 j)``.

    The lowest speed a decelerating state (``a < 0``) passes through, the highest an
    accelerating one (``a > 0``) reaches, whatever the jerk afterwards.

    Examples
    --------
    >>> turnaround_speed(1.9, 0.4, 0.5), turnaround_speed(1.0, -1.0, 0.5)
    (2.06, 0.0)
    """
    if not np.isfinite(j_max):
        return v
    return v + a * abs(a) / (2.0 * j_max)


@dataclass(frozen=True)
class Phase:
    """A constant-jerk phase: ``jerk`` [m/s³] during ``duration`` [s]."""

    jerk: float
    duration: float


def transition(v: float, a: float, v_target: float, a_target: float, j_max: float,
               a_max: float, a_decel: float) -> tuple[Phase, ...]:
    """Time-optimal change from ``(v, a)`` to ``(v_target, a_target)`` (speed and acceleration).

    Ramp the acceleration to a peak, hold it at ``a_max`` / ``-a_decel`` if the peak would
    exceed it, ramp to ``a_target``: the peak follows from the speed change in closed form.
    No speed limit is considered (the caller checks the turnaround speeds).

    Examples
    --------
    From rest to 1 m/s at rest acceleration with ``j = 0.5``, ``a_max = 1``: jerk ``+j`` for
    ``sqrt(v/j)`` = 1.414 s, then ``-j`` as long.

    >>> [(p.jerk, round(float(p.duration), 6)) for p in transition(0, 0, 1, 0, 0.5, 1, 1)]
    [(0.5, 1.414214), (0.0, 0.0), (-0.5, 1.414214)]
    """
    j = j_max
    # Speed when the acceleration is ramped straight from a to a_target (one jerk phase).
    direct = v + 0.5 * (a + a_target) * abs(a_target - a) / j
    up = v_target >= direct
    sign = 1.0 if up else -1.0
    limit = a_max if up else a_decel
    dv = (v_target - v) * sign
    peak_sq = j * dv + 0.5 * (a * a + a_target * a_target)
    peak = np.sqrt(max(peak_sq, 0.0))
    hold = 0.0
    if peak > limit:
        peak = limit
        hold = (dv - (2 * peak * peak - a * a - a_target * a_target) / (2.0 * j)) / peak
    ap = sign * peak
    return (Phase(sign * j, abs(ap - a) / j), Phase(0.0, max(hold, 0.0)),
            Phase(-sign * j, abs(ap - a_target) / j))


def run_phases(v: float, a: float, phases: tuple[Phase, ...]) -> tuple[float, float, float]:
    """Distance, final speed and acceleration after ``phases`` from ``(v, a)``."""
    s = 0.0
    for p in phases:
        t = p.duration
        s += v * t + 0.5 * a * t * t + p.jerk * t**3 / 6.0
        v += a * t + 0.5 * p.jerk * t * t
        a += p.jerk * t
    return s, v, a


def stop_distance(v: float, a: float, j_max: float, a_decel: float) -> float:
    """Shortest distance to rest (``v = a = 0``) from ``(v, a)``: the time-optimal braking.

    Examples
    --------
    From 1 m/s at rest acceleration, ``j = 0.5``: jerk ``-j`` for ``sqrt(v/j)`` = 1.414 s
    then ``+j`` as long; by symmetry the mean speed is ``v/2``: 1.414 m.

    >>> round(stop_distance(1.0, 0.0, 0.5, 1.0), 6)
    1.414214
    """
    return float(run_phases(v, a, transition(v, a, 0.0, 0.0, j_max, np.inf, a_decel))[0])


def min_distance(v0: float, a0: float, vf: float, af: float, j_max: float, a_max: float,
                 a_decel: float) -> float:
    """Shortest distance over which a jerk-limited motion goes from ``(v0, a0)`` to ``(vf, af)``.

    With an end at rest it is the time-optimal braking (or, time reversed, start); between
    two moving states the shorter of the time-optimal transition and the transitions through
    a speed minimum ``(v_m, 0)`` (the distance is minimised over ``v_m``).

    Examples
    --------
    >>> round(min_distance(0.0, 0.0, 1.0, 0.0, 0.5, 1.0, 1.0), 6)  # time reversal of a stop
    1.414214
    """
    if vf == 0.0 and af == 0.0:
        return stop_distance(v0, a0, j_max, a_decel)
    if v0 == 0.0 and a0 == 0.0:
        return stop_distance(vf, -af, j_max, a_max)

    def through(v_m: float) -> float:
        first = run_phases(v0, a0, transition(v0, a0, v_m, 0.0, j_max, a_max, a_decel))[0]
        second = run_phases(vf, -af, transition(vf, -af, v_m, 0.0, j_max, a_decel, a_max))[0]
        return first + second

    best = run_phases(v0, a0, transition(v0, a0, vf, af, j_max, a_max, a_decel))[0]
    low = max(0.0, min(turnaround_speed(v0, a0, j_max), turnaround_speed(vf, -af, j_max)))
    grid = np.linspace(0.0, low, 65)
    values = [through(float(vm)) for vm in grid]
    k = int(np.argmin(values))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
    for _ in range(60):  # golden-section refinement of the sampled minimum
        m1, m2 = lo + 0.382 * (hi - lo), lo + 0.618 * (hi - lo)
        if through(m1) <= through(m2):
            hi = m2
        else:
            lo = m1
    return float(min(best, values[k], through(0.5 * (lo + hi))))


def check_reachable_states(v0: float, a0: float, vf: float, af: float, length: float,
                           v_max: float, a_max: float, a_decel: float, j_max: float) -> None:
    """Raise `InfeasibleError` if no jerk-limited motion joins the states.

    The 1-D conditions, in closed form: the speed an accelerating start reaches before its
    acceleration can be brought to 0 (and the speed a decelerating end comes from) must not
    exceed ``v_max``; the speed a decelerating start falls to (an accelerating end comes from)
    must not be negative; the path must be at least as long as the shortest motion between
    the two states. A start whose speed falls exactly to 0 is reachable: the vehicle comes to
    rest on the way (the planner splits the path there).
    """
    if not np.isfinite(j_max):
        return
    tol = _SLACK * max(v_max, 1.0)
    checks = (
        ("v0", v0, "a0", a0, turnaround_speed(v0, a0, j_max), 0.0, "start"),
        ("vf", vf, "af", af, turnaround_speed(vf, -af, j_max), length, "end"),
    )
    for vname, v, aname, a, turn, where, which in checks:
        rising = a > 0 if which == "start" else a < 0
        if rising and turn > v_max + tol:
            verb = "reaches" if which == "start" else "comes from"
            raise InfeasibleError(
                f"`{vname}`={v:.6g} m/s with `{aname}`={a:.6g} m/s² is not reachable: a "
                f"jerk-limited vehicle {verb} at least {vname} + |{aname}|²/(2 j_max) = "
                f"{turn:.6g} m/s, above v_max={v_max:.6g} m/s (j_max={j_max:.6g} m/s³); lower "
                f"|{aname}| or {vname}",
                constraint="v_max", s=where,
            )
        if not rising and a != 0 and turn < -tol:
            verb = "falls to" if which == "start" else "would come from"
            raise InfeasibleError(
                f"`{vname}`={v:.6g} m/s with `{aname}`={a:.6g} m/s² is not reachable: its "
                f"speed {verb} {vname} - {aname}²/(2 j_max) = {turn:.6g} m/s < 0 "
                f"(j_max={j_max:.6g} m/s³); needs {vname} >= {a * a / (2 * j_max):.6g} m/s",
                constraint="jerk", s=where,
            )
    need = min_distance(v0, a0, vf, af, j_max, a_max, a_decel)
    if length < need * (1 - _SLACK):
        what = ("come to rest" if vf == 0.0 and af == 0.0 else
                f"reach vf={vf:.6g} m/s, af={af:.6g} m/s²")
        raise InfeasibleError(
            f"the path is too short: from v0={v0:.6g} m/s, a0={a0:.6g} m/s² a jerk-limited "
            f"vehicle needs at least {need:.6g} m to {what} (j_max={j_max:.6g} m/s³, "
            f"a_max={a_max:.6g}, a_decel={a_decel:.6g} m/s²); the path is {length:.6g} m",
            constraint="length", s=length,
        )

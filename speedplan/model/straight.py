"""Straight legs: the exact minimum-time motion in closed form, without a grid or a solver.

On a straight stretch (every piece a line) whose speed bound is one constant ``v_top``, the
curvature terms vanish (no lateral acceleration, lateral jerk or yaw rate) and planning is the
1-D time-optimal move under ``v <= v_top``, ``-a_decel <= a <= a_max``, ``|jerk| <= j_max``,
``v >= 0``. Its optimum rises from the start state ``(v0, a0)`` to a peak ``(vp, 0)`` with the
time-optimal change of speed and acceleration (jerk ramp to a peak acceleration, hold it at
``a_max`` if it would exceed it, ramp back to 0: `speedplan.model.boundary.transition`),
cruises at ``vp``, and falls to the end state ``(vf, af)`` likewise: the double-S move, seven
constant-jerk phases at most (`straight_motion`).

**The peak.** The peak must be at least the speed each state turns around at
(``v + a|a|/(2 j)``: a start's acceleration brought to 0, an end's traced back to 0). With
``D(vp)`` the distance of both changes and a cruise over the rest, the time is
``T_1 + T_2 + (L - D) / vp``; each change's time less its distance over ``vp`` falls as the
peak rises (a higher target raises the speed all along the change), and so does the cruise's
``(L - D) / vp``: the higher the peak, the shorter the move. So ``vp`` is ``v_top`` when both
changes fit in ``L`` (with a cruise), else the root of ``D(vp) = L`` (bracketed, monotone).
Between states at zero acceleration the changes are symmetric in time: a change over ``dv``
lasts ``dv/a + a/j`` (``2 sqrt(dv/j)`` when ``a`` is not reached) and covers its mean speed
times that. The ends' phases come out exactly — jerk phases of microseconds on a kilometre
move included, which no grid resolves.

**The valley.** When even the lowest admissible peak's changes are longer than ``L``, the
vehicle can only arrive by going slower first: it falls to a speed valley ``(vl, 0)`` and
rises from it (a start at 0.1 m/s that must reach 2 m/s over a stretch shorter than the
direct speed-up). Both changes are shorter in time the higher the valley, so the fastest has
the highest valley whose changes fit, spanning ``L`` exactly (`_valley_motion`).

**Where it is the optimum.** The time-optimal 1-D motion has at most seven constant-jerk
phases (Berscheid & Kröger, *Jerk-limited real-time trajectory generation with arbitrary
target states*, 2021); those that rise to one speed peak and fall from it, or fall to one
valley and rise from it, are this family. Between states at zero acceleration it holds every
motion there is. The others — a motion that never has a peak nor a valley (still
accelerating on arrival past any peak, say) — have no member here: `straight_motion` returns
``None`` and the leg is planned on a grid like any other — unless ``L`` is the length of the
shortest change between a moving state and rest itself (a state read off a plan's braking):
that change is then the only motion. ``tests/api/test_straight_moves.py`` holds every motion
of this family against ruckig's optimum over decades of scale, boundary states included.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from ..core.checks import FloatArray
from ..geometry import SpeedBound, bound_breakpoints
from .boundary import run_phases, transition, turnaround_speed
from .request import PlanRequest

__all__ = ["BOUNDARY_ROUNDING", "JerkPhases", "constant_bound", "straight_applies",
           "straight_motion"]

#: Boundary states this fraction beyond the reach of a motion of the family are on its
#: boundary up to rounding, as in the reachability test (`check_reachable_states`): an
#: accelerating start that turns around above ``v_top`` (a state read off a plan's rise to
#: ``v_max``), a stretch shorter than the shortest change between a moving state and rest
#: (one read off its braking). The turnaround speed, or the stop's length, is the plan's to
#: a few ulps either way.
BOUNDARY_ROUNDING = 1e-9


@dataclass(frozen=True, eq=False)
class JerkPhases:
    """A 1-D motion made of constant-jerk phases, given at the phases' boundaries.

    Attributes
    ----------
    t : ndarray
        Times of the boundaries [s], from 0, shape ``(m + 1,)``.
    s : ndarray
        Positions there [m], from 0.
    v, a : ndarray
        Speed [m/s] and acceleration [m/s²] there.
    jerk : ndarray
        Jerk of each phase [m/s³], shape ``(m,)``.
    """

    t: FloatArray
    s: FloatArray
    v: FloatArray
    a: FloatArray
    jerk: FloatArray

    @property
    def duration(self) -> float:
        """Total time [s]."""
        return float(self.t[-1])

    @property
    def length(self) -> float:
        """Distance covered [m]."""
        return float(self.s[-1])


def _change_time(dv: float, acc: float, j_max: float) -> float:
    """Duration of the time-optimal speed change by ``dv >= 0`` from and to ``a = 0``."""
    if dv * j_max <= acc * acc:
        return 2.0 * float(np.sqrt(dv / j_max))
    return dv / acc + acc / j_max


def _changes_distance(vp: float, v0: float, vf: float, a_max: float, a_decel: float,
                      j_max: float) -> float:
    """Distance of the speed changes ``v0 -> vp -> vf`` at zero acceleration (symmetric)."""
    return (0.5 * (v0 + vp) * _change_time(vp - v0, a_max, j_max)
            + 0.5 * (vp + vf) * _change_time(vp - vf, a_decel, j_max))


def _rise_distance(v: float, a: float, vp: float, j_max: float, acc: float, dec: float
                   ) -> float:
    """Distance of the time-optimal change from ``(v, a)`` to ``(vp, 0)``."""
    return run_phases(v, a, transition(v, a, vp, 0.0, j_max, acc, dec))[0]


def _rising(v0: float, a0: float, v_hi: float, j_max: float, acc: float, dec: float
            ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """Boundaries ``(t, d, v, a)`` and jerks of the time-optimal change ``(v0, a0) -> (v_hi, 0)``.

    ``d`` from 0 at the start; phases of zero duration are dropped, the end state is set
    exactly (``v_hi``, ``a = 0``).
    """
    phases = [p for p in transition(v0, a0, v_hi, 0.0, j_max, acc, dec) if p.duration > 0]
    m = len(phases)
    t, d, v, a = np.zeros(m + 1), np.zeros(m + 1), np.zeros(m + 1), np.zeros(m + 1)
    jerk = np.array([p.jerk for p in phases], dtype=np.float64)
    v[0], a[0] = v0, a0
    for k, p in enumerate(phases):
        dt = p.duration
        t[k + 1] = t[k] + dt
        d[k + 1] = d[k] + dt * (v[k] + dt * (0.5 * a[k] + dt * p.jerk / 6.0))
        v[k + 1] = v[k] + dt * (a[k] + 0.5 * dt * p.jerk)
        a[k + 1] = a[k] + dt * p.jerk
    v[-1], a[-1] = v_hi, 0.0
    return t, d, v, a, jerk


def straight_motion(length: float, v0: float, vf: float, v_top: float, a_max: float,
                    a_decel: float, j_max: float, *, a0: float = 0.0,
                    af: float = 0.0) -> JerkPhases | None:
    """The minimum-time double-S move over ``length`` from ``(v0, a0)`` to ``(vf, af)``.

    Parameters
    ----------
    length : float
        Distance [m], > 0.
    v0, vf : float
        Speeds at the start and the end [m/s], ``<= v_top``.
    v_top : float
        Speed limit over the whole stretch [m/s].
    a_max, a_decel, j_max : float
        Acceleration, braking [m/s²] and jerk [m/s³] limits (finite).
    a0, af : float
        Accelerations at the start and the end [m/s²], within ``[-a_decel, a_max]``.

    Returns
    -------
    JerkPhases or None
        The motion (see the module notes for when it is the optimum), or ``None`` when no
        motion through one speed peak or one speed valley joins the states within
        ``length`` and ``v_top`` (the states then need a grid, or no motion joins them) —
        unless the stretch is as long as the shortest change from a moving state to rest
        (or from rest to a moving state), to `BOUNDARY_ROUNDING`: that change is the only
        motion (`_forced_change`).

    Examples
    --------
    30 m from rest to rest with ``v_max = 2``, ``a_max = 1``, ``j_max = 0.5``: 4 s to reach
    2 m/s (jerk phases of 2 s, no constant acceleration), 11 s of cruise, 4 s to stop.

    >>> m = straight_motion(30.0, 0.0, 0.0, 2.0, 1.0, 1.0, 0.5)
    >>> round(m.duration, 12), m.jerk.tolist()
    (19.0, [0.5, -0.5, 0.0, -0.5, 0.5])
    """
    if not (length > 0 and v_top > 0 and np.isfinite(j_max)):
        return None
    turns = (turnaround_speed(v0, a0, j_max), turnaround_speed(vf, -af, j_max))
    low = max(turns)
    if min(turns) < 0 or low > v_top * (1.0 + BOUNDARY_ROUNDING):
        return None
    low = min(low, v_top)  # a start turning around a rounding above v_top ends at it
    if a0 == 0.0 and af == 0.0:
        def distance(vp: float) -> float:
            return _changes_distance(vp, v0, vf, a_max, a_decel, j_max)
    else:
        def distance(vp: float) -> float:
            return (_rise_distance(v0, a0, vp, j_max, a_max, a_decel)
                    + _rise_distance(vf, -af, vp, j_max, a_decel, a_max))
    if distance(low) > length:
        forced = _forced_change(length, v0, a0, vf, af, a_max, a_decel, j_max)
        return forced if forced is not None else _valley_motion(length, v0, a0, vf, af, a_max,
                                                                a_decel, j_max)
    vp = v_top if distance(v_top) <= length else _root(distance, length, low, v_top)
    return _joined(length, vp, low, v0, a0, vf, af, a_max, a_decel, j_max)


def _root(distance: Callable[[float], float], length: float, lo: float, hi: float) -> float:
    """The speed in ``[lo, hi]`` where ``distance`` equals ``length``, to a few ulps.

    An absolute tolerance in the speed left a peak 1e5 times below ``v_top`` 7e-6 short of
    the root, and a cruise at it in place of the jerk phases.
    """
    return float(brentq(lambda x: distance(x) - length, lo, hi, xtol=np.finfo(float).tiny,
                        rtol=4 * np.finfo(float).eps))


#: Speeds at which the valley's distance is evaluated between the turnaround speed and
#: rest, to bracket its largest root (`_valley_motion`).
VALLEY_SCAN = 64


def _valley_motion(length: float, v0: float, a0: float, vf: float, af: float, a_max: float,
                   a_decel: float, j_max: float) -> JerkPhases | None:
    """The fastest motion over ``length`` that falls to one speed valley and rises from it.

    Where even the lowest peak's changes are longer than the stretch, the vehicle can only
    arrive by going slower first: a fall from ``(v0, a0)`` to a valley ``(vl, 0)`` and a
    rise to ``(vf, af)``, each time-optimal. The higher the valley, the shorter both changes
    in time and the longer in distance near it, so the fastest motion has the highest valley
    whose changes fit, and they span ``length`` exactly: the largest root of
    ``D(vl) = length`` below the lowest turnaround speed. ``D`` is not monotone (a change's
    distance falls again as the valley nears rest, where the speed is low all along it), so
    the root is bracketed by scanning down from the turnaround speed; at rest the motion
    is a stop and a start again. ``None`` when not even those fit: a motion still
    accelerating on arrival, or none at all.
    """
    high = min(turnaround_speed(v0, a0, j_max), turnaround_speed(vf, -af, j_max))
    if not high > 0.0:
        return None

    def distance(vl: float) -> float:
        return (_rise_distance(v0, a0, vl, j_max, a_max, a_decel)
                + _rise_distance(vf, -af, vl, j_max, a_decel, a_max))

    if not distance(high) > length:
        return None
    above = high
    for vl in high * np.linspace(1.0, 0.0, VALLEY_SCAN + 1)[1:]:
        if distance(vl) <= length:
            valley = _root(distance, length, vl, above)
            break
        above = vl
    else:  # a stop and a start again, if they span the stretch to a rounding
        valley = 0.0
    # No cruise at the valley: the changes span the stretch to a rounding, which a cruise at
    # a valley next to rest would turn into seconds. They are stretched over it instead.
    up = _rising(v0, a0, valley, j_max, a_max, a_decel)
    down = _rising(vf, -af, valley, j_max, a_decel, a_max)
    spanned = float(up[1][-1] + down[1][-1])
    if not abs(length - spanned) <= BOUNDARY_ROUNDING * length:
        return None
    return _stretched(_assembled(spanned, up, down, 0.0), length / spanned)


def _joined(length: float, vm: float, fits: float, v0: float, a0: float, vf: float,
            af: float, a_max: float, a_decel: float, j_max: float) -> JerkPhases:
    """The changes ``(v0, a0) -> (vm, 0) -> (vf, af)``, a cruise at ``vm`` over the rest.

    ``fits``: a speed below ``vm`` whose changes fit in ``length``.
    """
    for k in range(60):
        up = _rising(v0, a0, vm, j_max, a_max, a_decel)
        # The second change, time reversed, is a change from (vf, -af): its positions
        # counted from the end keep full precision next to a final stop.
        down = _rising(vf, -af, vm, j_max, a_decel, a_max)
        gap = length - down[1][-1] - up[1][-1]
        if gap >= 0.0 or vm <= fits:
            break
        # The changes overlap by a rounding (a change of a few ulps of speed computed from a
        # difference of speeds): a hair lower middle speed leaves a cruise of a rounding
        # instead, so that the positions of both changes meet without a jump.
        vm = max(fits, vm - (vm - fits) * 2.0 ** (k - 50))
    return _assembled(length, up, down, max(gap, 0.0) / vm)


def _assembled(length: float, up: tuple[FloatArray, ...], down: tuple[FloatArray, ...],
               cruise: float) -> JerkPhases:
    """The change ``up`` (`_rising`), a cruise of ``cruise`` seconds, then ``down`` reversed."""
    t_up, d_up, v_up, a_up, j_up = up
    t_dn, d_dn, v_dn, a_dn, j_dn = down
    starts = [t_up, t_up[-1] + cruise + (t_dn[-1] - t_dn[::-1])]
    pos = [d_up, length - d_dn[::-1]]
    speed, acc, jerk = [v_up, v_dn[::-1]], [a_up, -a_dn[::-1]], [j_up, j_dn[::-1]]
    if cruise > 0:
        jerk.insert(1, np.zeros(1))
    else:  # the two changes meet: one boundary between them
        starts[1], pos[1], speed[1], acc[1] = (x[1:] for x in (starts[1], pos[1], speed[1],
                                                               acc[1]))
    return JerkPhases(t=np.concatenate(starts), s=np.concatenate(pos),
                      v=np.concatenate(speed), a=np.concatenate(acc),
                      jerk=np.concatenate(jerk))


def _stretched(motion: JerkPhases, k: float) -> JerkPhases:
    """``motion`` slowed down in time by ``k``: positions and times times ``k``.

    The same speeds, accelerations over ``k`` and jerks over ``k²``; the phases stay
    consistent (positions scaled alone would jump by ``(k - 1) s`` inside each phase).
    """
    return JerkPhases(t=motion.t * k, s=motion.s * k, v=motion.v, a=motion.a / k + 0.0,
                      jerk=motion.jerk / (k * k))


def _forced_change(length: float, v0: float, a0: float, vf: float, af: float, a_max: float,
                   a_decel: float, j_max: float) -> JerkPhases | None:
    """The time-optimal change between a moving state and rest, if it spans ``length``.

    From ``(v0, a0)`` to rest the shortest motion is the time-optimal braking (time
    reversed, from rest to ``(vf, af)`` the time-optimal start); over a stretch that long,
    to `BOUNDARY_ROUNDING`, it is the only motion. A state read off a plan's braking (its
    acceleration still falling, or held at ``-a_decel``) lies there: no motion with a speed
    peak joins it to rest. ``None`` elsewhere.

    The change is stretched in time by ``k = length / distance`` (`_stretched`, a
    rounding) to cover ``length`` exactly.
    """
    if vf == 0.0 and af == 0.0 and v0 > 0.0:
        t, d, v, a, jerk = _rising(v0, a0, 0.0, j_max, a_max, a_decel)
    elif v0 == 0.0 and a0 == 0.0 and vf > 0.0:  # time reversed, from the end
        t, d, v, a, jerk = _rising(vf, -af, 0.0, j_max, a_decel, a_max)
        t, d, v, a, jerk = t[-1] - t[::-1], d[-1] - d[::-1], v[::-1], -a[::-1], jerk[::-1]
    else:
        return None
    if jerk.size == 0 or not abs(d[-1] - length) <= BOUNDARY_ROUNDING * length:
        return None
    return _stretched(JerkPhases(t=t, s=d, v=v, a=a, jerk=jerk), length / d[-1])


def constant_bound(bound: SpeedBound, lo: float, hi: float) -> float | None:
    """The speed bound's value [m²/s²] if it is one constant over ``[lo, hi]``, else ``None``.

    Evaluated at the ends, at every breakpoint inside (piece joins, zone entries and exits,
    ``v_limit`` knots, span ends: `bound_breakpoints`) and between consecutive ones; on a
    straight stretch the bound is piecewise constant or linear between breakpoints, so equal
    values there mean a constant bound. The ends are read one ulp inside the stretch: at a
    join the bound is that of the piece (zone, span) beginning there, which the stretch only
    touches — a line ending at a stop where an arc begins has the line's bound up to it.
    """
    breaks = bound_breakpoints(bound.path, bound)
    inner = breaks[(breaks > lo) & (breaks < hi)]
    knots = np.concatenate(([lo], inner, [hi]))
    ends = np.array([np.nextafter(lo, hi), np.nextafter(hi, lo)])
    probes = np.concatenate((ends, inner, 0.5 * (knots[:-1] + knots[1:])))
    w = np.asarray(bound(probes), dtype=np.float64)
    top = float(w[0])
    return top if top > 0 and np.isfinite(top) and bool(np.all(w == top)) else None


def straight_applies(request: PlanRequest, lo: float, hi: float) -> bool:
    """Whether the stretch ``[lo, hi]`` of ``request`` is planned in closed form.

    A straight stretch, jerk-limited with the smooth standstill, on the default grid (``n``
    and ``ds`` not given: a given grid is the caller's) with ``backend="auto"`` (a named
    backend asks for the relaxation). The speed bound is checked separately
    (`constant_bound`), and whether a double-S move joins the states (`straight_motion`).
    """
    return (request.jerk_limited and request.smooth_standstill
            and request.n is None and request.ds is None and request.backend == "auto"
            and request.path.straight_between(lo, hi))

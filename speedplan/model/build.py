"""From a physical request to its model: the legs between standstills and their problems.

`build_model` is the one place where limits in SI units become the rows of a
[`DiscreteProblem`][speedplan.DiscreteProblem]. A request is split into *legs* at every point
where the vehicle must be at rest: where a boundary state forces a stop on the way (a
decelerating start whose speed falls exactly to zero: the motion to that point is forced, a
`ForcedLeg`), and — with the route and cusp support — at cusps and stops. A straight stretch
with a constant speed bound whose states a motion with one speed peak joins is a
`StraightLeg`: its minimum-time motion is known in closed form (`speedplan.model.straight`).
Every other `Leg` gets its grid (`speedplan.model.leg_grid`), its node bounds, envelopes and
lateral rows (`speedplan.model.rows`) and is planned on its own by `speedplan.strategy`. This
layer builds data and calls no solver.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..core.checks import FloatArray
from ..core.errors import InfeasibleError, InvalidInputError
from ..core.options import RestReason
from ..geometry import CellSamples, SpeedBound, bound_breakpoints
from ..geometry.bounds import check_v_limit
from ..solve.problem import MAX_RAMP_STEPS, DiscreteProblem, ramp_steps
from .boundary import STATE_JERK_ROUNDING, check_reachable_states, turnaround_speed
from .grid import MIN_NODES
from .leg_grid import default_grid, grid_anchors, kink_anchors, leg_grid, no_jerk_grid
from .legs import ForcedLeg, Leg, Model, ModelLeg, Rest, StraightLeg, TimeLawSpec, TurnLeg
from .request import STATE_ROUNDING, PlanRequest, within_limit
from .rows import (
    Envelopes,
    check_floor,
    chord_node_bounds,
    curvature_at_nodes,
    lateral_jerk_rows,
    lateral_speed_caps,
    node_minima,
)
from .standstill import calibrate_standstill_rows
from .straight import JerkPhases, constant_bound, straight_applies, straight_motion

__all__ = ["FORCED_NODES", "TOUCH_TIME", "TOUCH_ZERO", "build_leg", "build_model",
           "leg_on_grid", "rest_points", "straight_leg"]

#: A decelerating boundary state whose speed falls to within this fraction of its own speed
#: (``v - a²/(2 j)``) of zero comes to rest on the way: the gain of passing through at that
#: speed is below any resolvable time, and the dip could not be gridded.
TOUCH_ZERO = 1e-6
#: ... or when passing through the dip instead of restarting from rest gains less than this
#: fraction of the move's least duration (far below the 1e-4 of the optimum plans promise).
TOUCH_TIME = 1e-6


#: Nodes of the sampled forced motion of a `ForcedLeg`.
FORCED_NODES = 401


def rest_points(request: PlanRequest) -> tuple[Rest, ...]:
    """Where the vehicle must be at rest inside the path: cusps, asked stops, curvature jumps.

    Points closer than ``1e-9`` of the length merge (the first reason listed wins: a cusp,
    then a stop, then a curvature jump).
    """
    path = request.path
    length = float(path.length)
    found = [Rest(float(s), "cusp") for s in path.cusps]
    found += [Rest(float(s), "stop") for s in request.stops]
    if np.isfinite(request.limits.j_lat_max):
        found += [Rest(float(s), "curvature jump") for s in path.curvature_jumps()[0]]
    order: dict[RestReason, int] = {"cusp": 0, "stop": 1, "curvature jump": 2}
    out: list[Rest] = []
    for rest in sorted(found, key=lambda r: (r.s, order[r.reason])):
        if not 0.0 < rest.s < length:
            continue
        if out and rest.s - out[-1].s <= 1e-9 * length:
            continue
        out.append(rest)
    return tuple(out)


def build_model(request: PlanRequest) -> Model:
    """Model ``request``: split it into legs and build each leg's discrete problem.

    The path is cut at every `Rest` (`rest_points`); each stretch between two
    cuts runs from its start state (the request's at ``s = 0``, rest elsewhere) to its end
    state, and becomes one `Leg`, preceded (followed) by a `ForcedLeg` where
    its start (end) state forces a stop on the way.

    Raises
    ------
    InvalidInputError
        A boundary speed above the speed bound, or a speed bound of 0 inside the path.
    InfeasibleError
        A boundary state no jerk-limited motion can leave or reach (which state, which
        limit), or a stretch too short to join the states at its ends (which, where).
    """
    lim = request.limits
    path = request.path
    length = float(path.length)
    bound = SpeedBound(path, lim, None if request.zones is None else list(request.zones),
                       request.v_limit, spans=request.spans).memoised()
    request = _end_speeds(request, bound, length)
    rests = rest_points(request)
    cuts = [0.0, *(r.s for r in rests), length]
    legs: list[ModelLeg] = []
    for j in range(len(cuts) - 1):
        first, last = j == 0, j == len(cuts) - 2
        legs += _stretch_legs(
            request, bound, cuts[j], cuts[j + 1],
            (request.v0, request.a0) if first else (0.0, 0.0),
            (request.vf, request.af) if last else (0.0, 0.0),
            None if first else rests[j - 1], None if last else rests[j],
        )
    return Model(request=request, bound=bound, legs=tuple(legs), rests=rests)


def _stretch_legs(request: PlanRequest, bound: SpeedBound, lo: float, hi: float,
                  start: tuple[float, float], end: tuple[float, float], rest_before: Rest | None,
                  rest_after: Rest | None) -> list[ModelLeg]:
    """The legs of the stretch ``[lo, hi]`` between two cuts (the path's ends or rests)."""
    turned = None if request.turn_jerk is None else _turned_ends(request, bound, lo, hi, start,
                                                                 end)
    if turned is not None:
        first, last = turned
        inner = _stretch_legs(
            replace(request, turn_jerk=None), bound,
            lo + (first.length if first else 0.0), hi - (last.length if last else 0.0),
            (first.vf, 0.0) if first else start, (last.v0, 0.0) if last else end,
            rest_before, rest_after)
        return [*([first] if first else []), *inner, *([last] if last else [])]
    lim = request.limits
    (v0, a0), (vf, af) = start, end
    length = hi - lo
    if request.jerk_limited:
        _check_stretch_states(request, lo, hi, start, end, rest_before, rest_after)
    legs: list[ModelLeg] = []
    j_state = request.leg_jerk(v0, a0, vf, af)
    # A state read off a plan's final stop (it needs the rounding jerk) lies on the stop's
    # curve to the law's rounding, a few 1e-5: it touches zero within a few times that, and
    # its own stop, like a³/j², ends a few times that before or past the stretch's end.
    rounded = lim.j_max < j_state <= lim.j_max * (1.0 + STATE_JERK_ROUNDING)
    touch = max(TOUCH_ZERO, 4.0 * STATE_JERK_ROUNDING) if rounded else TOUCH_ZERO
    past = 5.0 * STATE_JERK_ROUNDING if rounded else STATE_ROUNDING
    touching = {"touch": touch, "least_duration": length / lim.v_max}
    # In closed form a speed dip next to rest is exact: only a state that stops on the way
    # (`_stops_in_closed_form`) is planned as a stop and the rest of the stretch.
    if request.jerk_limited and not any(
            _stops_in_closed_form(v, a, j_state, end=end, touch=touch, rounded=rounded,
                                  spans=(length, past))
            for v, a, end in ((v0, a0, False), (vf, af, True))):
        whole = straight_leg(request, bound, lo, hi, v0, a0, vf, af)
        if whole is not None:
            return [whole]
    head = _forced_stop(v0, a0, j_state, end=False, **touching) if request.jerk_limited else None
    tail = _forced_stop(vf, af, j_state, end=True, **touching) if request.jerk_limited else None
    inner_lo, inner_hi = lo, hi
    for forced in (head, tail):
        if forced is not None and forced.length > length * (1.0 + past):
            state = (f"v0={v0:.6g} m/s, a0={a0:.6g} m/s²" if forced is head
                     else f"vf={vf:.6g} m/s, af={af:.6g} m/s²")
            raise InfeasibleError(
                f"the stretch from s={lo:.6g} m to s={hi:.6g} m is too short for the state "
                f"{state}: it forces a stop (+j_max until at rest) {forced.length:.6g} m long, "
                f"and {length:.6g} m are left", constraint="length", s=hi)
        if forced is not None and abs(forced.length - length) <= past * length:
            # A state on a stop's curve a rounding before or past the stretch's end: its stop
            # spans the stretch.
            forced = _spanning(forced, length)
            head, tail = (forced, None) if forced.v0 > 0 else (None, forced)
    # A forced stop whose acceleration and duration are roundings (a state a few ulps from
    # rest) is no motion: the state is rest.
    if head is not None and _no_motion(head, lim.a_decel, touching["least_duration"]):
        head, v0, a0 = None, 0.0, 0.0
    if tail is not None and _no_motion(tail, lim.a_max, touching["least_duration"]):
        tail, vf, af = None, 0.0, 0.0
    if head is not None:
        legs.append(_shifted(head, lo))
        inner_lo, v0, a0 = lo + head.length, 0.0, 0.0
    if tail is not None:
        inner_hi, vf, af = hi - tail.length, 0.0, 0.0
    if inner_hi - inner_lo > 1e-12 * length:
        legs.append(straight_leg(request, bound, inner_lo, inner_hi, v0, a0, vf, af)
                    or build_leg(request, bound, inner_lo, inner_hi, v0, a0, vf, af))
    elif head is not None and tail is not None:
        raise InfeasibleError(
            "the path is too short: both boundary states force a stop and the two stops "
            "overlap", constraint="length", s=hi)
    if tail is not None:
        legs.append(_shifted(tail, hi - tail.length))
    return legs


def _check_stretch_states(request: PlanRequest, lo: float, hi: float,
                          start: tuple[float, float], end: tuple[float, float],
                          rest_before: Rest | None, rest_after: Rest | None) -> None:
    """`check_reachable_states` of a stretch; a refusal next to a rest names that rest."""
    lim = request.limits
    try:
        check_reachable_states(*start, *end, hi - lo, lim.v_max, lim.a_max, lim.a_decel,
                               request.leg_jerk(*start, *end))
    except InfeasibleError as exc:
        if rest_before is None and rest_after is None:
            raise
        ends = " and ".join(
            f"the {r.reason} at s={r.s:.6g} m" for r in (rest_before, rest_after)
            if r is not None)
        raise InfeasibleError(
            f"between s={lo:.6g} m and s={hi:.6g} m ({ends}, where the vehicle must be at "
            f"rest): {exc}", constraint=exc.constraint,
            s=None if exc.s is None else lo + exc.s) from exc


def _turned_ends(request: PlanRequest, bound: SpeedBound, lo: float, hi: float,
                 start: tuple[float, float], end: tuple[float, float]
                 ) -> tuple[TurnLeg | None, TurnLeg | None] | None:
    """The turns of the boundary states ``j_max`` does not reach (`TurnLeg`), or ``None``.

    With ``request.turn_jerk``: a state whose speed ``j_max`` cannot keep within
    ``[0, v_max]`` while its acceleration is brought to 0 gets that turn at constant jerk, at
    most ``turn_jerk`` (an overshooting state the least jerk that stays under ``v_max``, a
    dipping one ``turn_jerk``, which keeps its speed highest); the other state keeps
    ``j_max``. ``None`` when neither needs a turn, or a turn would not fit: longer than the
    stretch, or above the speed bound on its way (the caller then plans the whole move with
    the looser jerk).
    """
    lim = request.limits
    jerk = float(request.turn_jerk or lim.j_max)
    turns = [_turn(v, a, lim.j_max, jerk, lim.v_max, end=is_end)
             for (v, a), is_end in ((start, False), (end, True))]
    if turns == [None, None]:
        return None
    head = None if turns[0] is None else TurnLeg(
        start=lo, length=turns[0].length, v0=start[0], a0=start[1], vf=float(turns[0].v[-1]),
        af=0.0, motion=turns[0])
    tail = None if turns[1] is None else TurnLeg(
        start=hi - turns[1].length, length=turns[1].length, v0=float(turns[1].v[0]), a0=0.0,
        vf=end[0], af=end[1], motion=turns[1])
    taken = sum(t.length for t in (head, tail) if t is not None)
    if taken >= hi - lo:
        return None
    for leg in (head, tail):
        if leg is None:
            continue
        frac = np.linspace(0.0, 1.0, 17)
        t = frac * leg.motion.duration
        m = leg.motion
        d = t * (m.v[0] + t * (0.5 * m.a[0] + t * m.jerk[0] / 6.0))
        v = m.v[0] + t * (m.a[0] + 0.5 * t * m.jerk[0])
        top = np.asarray(bound(np.clip(leg.start + d, lo, hi)), dtype=np.float64)
        if np.any(v * v > top * (1.0 + 1e-9)):
            return None
    return head, tail


def _turn(v: float, a: float, j_max: float, jerk: float, v_max: float, *, end: bool
          ) -> JerkPhases | None:
    """The constant-jerk turn of the state ``(v, a)`` to zero acceleration, if it needs one.

    ``None`` where ``j_max`` alone keeps its speed within ``[0, v_max]`` (no turn needed) or
    ``jerk`` does not (no turn helps). At the end of a move (``end``) the turn arrives at
    ``(v, a)`` from zero acceleration (the time reversal of the start's).
    """
    rise = a if not end else -a  # > 0: the speed rises while the acceleration is brought to 0
    if rise == 0.0 or v <= 0.0:
        return None
    tol = 1e-9 * max(v_max, 1.0)
    if rise > 0:
        if turnaround_speed(v, rise, j_max) <= v_max + tol or v >= v_max:
            return None
        j = rise * rise / (2.0 * (v_max - v))  # the least jerk that stays under v_max
        after = v_max
    else:
        if turnaround_speed(v, rise, j_max) >= -tol:
            return None
        j = jerk
        after = turnaround_speed(v, rise, jerk)
        if after <= TOUCH_ZERO * v:  # it stops on the way: a forced stop, not a turn
            return None
    if j > jerk * (1.0 + 1e-12):
        return None
    dt = abs(rise) / j
    jerk_signed = -np.sign(rise) * j
    length = dt * (v + dt * (0.5 * rise + dt * jerk_signed / 6.0))
    if not end:
        return JerkPhases(t=np.array([0.0, dt]), s=np.array([0.0, length]),
                          v=np.array([v, after]), a=np.array([rise, 0.0]),
                          jerk=np.array([jerk_signed]))
    return JerkPhases(t=np.array([0.0, dt]), s=np.array([0.0, length]), v=np.array([after, v]),
                      a=np.array([0.0, a]), jerk=np.array([a / dt]))


def straight_leg(request: PlanRequest, bound: SpeedBound, lo: float, hi: float, v0: float,
                 a0: float, vf: float, af: float) -> StraightLeg | None:
    """The stretch ``[lo, hi]`` as a `StraightLeg` (its motion in closed form), or ``None``.

    ``None`` where the closed form does not apply (`straight_applies`, `constant_bound`)
    or no double-S move joins the states (`straight_motion`): the leg is then built on a grid.
    """
    if not straight_applies(request, lo, hi):
        return None
    top = constant_bound(bound, lo, hi)
    if top is None:
        return None
    lim = request.limits
    # The jerk a marginal boundary state may use (a state read off a plan lies on the
    # boundary of what j_max reaches, to rounding), as on a grid: over the whole leg.
    motion = straight_motion(hi - lo, v0, vf, float(np.sqrt(top)), lim.a_max, lim.a_decel,
                             request.leg_jerk(v0, a0, vf, af), a0=a0, af=af)
    if motion is None:
        return None
    return StraightLeg(start=lo, length=hi - lo, v0=v0, a0=a0, vf=vf, af=af, motion=motion)


def build_leg(request: PlanRequest, bound: SpeedBound, lo: float, hi: float, v0: float,
              a0: float, vf: float, af: float) -> Leg:
    """The discrete problem of the stretch ``[lo, hi]`` of the request's path."""
    leg_bound = bound if (lo == 0.0 and hi == float(request.path.length)) else _sub_bound(
        request, bound, lo, hi)
    if request.n is None and request.ds is None and not request.jerk_limited:
        samples = no_jerk_grid(request, leg_bound, hi - lo, v0, vf)  # the bound comes with it
        return leg_on_grid(request, leg_bound, samples.s, lo, v0, a0, vf, af, samples=samples)
    s = leg_grid(request, leg_bound, lo, hi, v0, a0, vf, af)
    if request.n is None and request.ds is None and request.jerk_limited:
        leg = leg_on_grid(request, leg_bound, s, lo, v0, a0, vf, af)
        steps = ramp_steps(leg.problem)
        if steps <= MAX_RAMP_STEPS:
            return leg
        # A default grid the relaxation cannot resolve (a millimetre move whose boundary
        # transients ask for micrometre steps): coarser everywhere, in proportion.
        s = default_grid(request, leg_bound, lo, hi, v0, a0, vf, af,
                         max(int(s.size * 0.9 * MAX_RAMP_STEPS / steps), MIN_NODES))
    return leg_on_grid(request, leg_bound, s, lo, v0, a0, vf, af)


def leg_on_grid(request: PlanRequest, bound: SpeedBound, s: FloatArray, lo: float, v0: float,
                a0: float, vf: float, af: float, samples: CellSamples | None = None) -> Leg:
    """The leg's discrete problem on the grid ``s`` (from 0 to the leg's length).

    A leg whose law is linear in ``w`` (no jerk nor lateral-jerk limit) keeps the bound at the
    grid's `cell_points` (``samples``, evaluated here unless given for ``s``): its node
    bounds come from them, and its law's check reads them (`Leg.samples`).
    """
    lim = request.limits
    length = float(s[-1])
    env = Envelopes.of(request, v0, a0, vf, af, length)
    linear = not (request.jerk_limited or np.isfinite(lim.j_lat_max))
    breaks = None
    if linear:
        if samples is None or samples.s is not s:
            samples = CellSamples.of(bound, s)
        w_max = env.cap(s, node_minima(samples.bound))
    else:
        samples = None
        breaks = bound_breakpoints(request.path, bound)
        w_max = env.cap(s, chord_node_bounds(bound, s, breaks))
    w_max[0] = max(w_max[0], v0 * v0)
    w_max[-1] = max(w_max[-1], vf * vf)
    if (w_max[1:-1] <= 0).any():
        zero = np.flatnonzero(w_max[1:-1] <= 0) + 1
        # A node bound is the least over the node's cells: say where the bound itself is 0.
        at = np.flatnonzero(bound(s[zero]) <= 0)
        i = int(zero[at[0] if at.size else 0])
        raise InvalidInputError(
            f"the speed bound is 0 at s={lo + s[i]:.6g} m inside the path ({_zero_cause(bound)}); "
            "split the path there to plan a stop"
        )
    m = s.size
    accel, decel = np.full(m - 1, lim.A), np.full(m - 1, lim.A_decel)
    curvature = None
    if np.isfinite(lim.j_lat_max):
        curvature = curvature_at_nodes(request.path, lo, s)  # for the caps and the rows alike
        w_max[1:-1] = np.minimum(w_max[1:-1], lateral_speed_caps(
            request.path, lo, s, lim.j_lat_max, accel, decel, node_curvature=curvature))
    floor = env.floor(s)
    if floor is not None:
        # Against the bound at the nodes themselves: the node bound (its minimum over the
        # adjacent cells) is below it where the bound falls, and a state read off a plan
        # braking into a curve is that close to the slowest motion (the U-turn at t = 7.8 s).
        check_floor(floor, np.maximum(w_max, env.cap(s, np.asarray(bound(s), dtype=np.float64))),
                     s, lo, v0, a0, vf, af)
        w_max[1:-1] = np.maximum(w_max[1:-1], floor[1:-1])
    jerk = np.full(m - 2, lim.J)
    j_leg = request.leg_jerk(v0, a0, vf, af)
    if j_leg != lim.j_max:  # the slack of a marginal state, over the whole leg
        jerk[:] = 2.0 * j_leg
    if request.smooth_standstill:
        calibrate_standstill_rows(jerk, s, v0, a0, vf, af, lim.j_max)
    problem = DiscreteProblem(
        s=s, w_max=w_max, accel=accel, decel=decel,
        jerk=jerk, w_start=v0 * v0, w_end=vf * vf, w_min=floor,
        lateral=lateral_jerk_rows(request.path, lo, s, lim.j_lat_max,
                                  node_curvature=curvature),
        grip=np.abs(request.path.curvature(lo + s)) / lim.a_lat_max if lim.ellipse else None,
    )
    law = TimeLawSpec(
        j_max=lim.j_max if request.smooth_standstill else None,
        accel_start=a0 if v0 > 0 and request.jerk_limited else None,
        accel_end=af if vf > 0 and request.jerk_limited else None,
        # Without jerk (and lateral-jerk) rows nothing bounds the law's bend: on the chords.
        linear=linear,
    )
    joins = grid_anchors(request, lo, lo + length)
    kinks = kink_anchors(request, bound, length, breaks)
    return Leg(start=lo, length=length, v0=v0, a0=a0, vf=vf, af=af, bound=bound,
               problem=problem, time_law=law, limits=lim, refine=request.refine,
               backend=request.backend,
               anchors=np.union1d(joins, kinks) if joins.size or kinks.size else joins,
               samples=samples)


def _zero_cause(bound: SpeedBound) -> str:
    if bound.zones and any(z.v_max == 0 for z in bound.zones):
        return "a zone with v_max=0 stops the vehicle"
    if bound.v_limit is not None and bool(np.any(np.asarray(bound.v_limit[1]) == 0)):
        return ("a knot of v_limit at 0 m/s: the bound falls to 0 there, and a bound that "
                "rises from 0 only in proportion to the distance cannot be left in finite time")
    return ("infinite curvature, e.g. a sharp polyline corner: round the corners "
            "(Path.from_waypoints with the default kind)")


def _end_speeds(request: PlanRequest, bound: SpeedBound, length: float) -> PlanRequest:
    """``request`` with ``v0``, ``vf`` under the speed bound at the ends, or an error.

    A speed above the bound by at most `STATE_ROUNDING` is
    taken at the bound (a state read off a plan: the time law's rounding).
    """
    if request.v0 == 0.0 and request.vf == 0.0:  # at rest: under any bound, which is >= 0
        if bound.v_limit is not None:  # refused here, as evaluating the bound would
            check_v_limit(bound.v_limit)
        return request
    ends = np.sqrt(bound.evaluate(np.array([0.0, length]))[1])
    v0, vf = (within_limit(name, v, float(b), "m/s", f"the speed bound at s={where:.6g} m "
                           "(v_max, lateral acceleration, a zone or v_limit)")
              for name, v, b, where in (("v0", request.v0, ends[0], 0.0),
                                        ("vf", request.vf, ends[1], length)))
    if (v0, vf) == (request.v0, request.vf):
        return request
    return replace(request, v0=v0, vf=vf)


def _forced_stop(v: float, a: float, j_max: float, *, end: bool, touch: float,
                 least_duration: float) -> ForcedLeg | None:
    """The forced motion to rest when a decelerating start (accelerating end) touches zero.

    ``j_max``: the jerk the state may use (`PlanRequest.leg_jerk`). It touches
    zero when the speed falls to within ``touch`` of its own (`TOUCH_ZERO`), or so
    close to zero that restarting from rest would cost less than `TOUCH_TIME` of
    ``least_duration`` (the stretch's length over ``v_max``): a dip the grid cannot resolve
    (a 1.9 km move from 1.5e-5 m/s braking at 0.019 m/s² dips to 9e-9 m/s).
    """
    slowing = -a if not end else a
    if not (v > 0 and slowing > 0):
        return None
    dip = turnaround_speed(v, -slowing, j_max)
    # The optimum passes the dip and speeds up again; from rest it needs 2 sqrt(2 dip / j)
    # longer, which below TOUCH_TIME of the move's least duration no plan resolves.
    restart = 2.0 * float(np.sqrt(2.0 * max(dip, 0.0) / j_max))
    if dip > touch * v and restart > TOUCH_TIME * least_duration:
        return None
    # v = slowing²/(2 j) with j = slowing²/(2 v) <= j_max: the forced motion is that max-jerk
    # stop, time reversed, so u = w^{3/4} falls linearly to 0 over its length |a|³ / (6 j²).
    j_max = min(j_max, slowing**2 / (2.0 * v))
    length = slowing**3 / (6.0 * j_max**2)
    frac = np.linspace(0.0, 1.0, FORCED_NODES)
    s = frac * length
    if end:  # from rest at the leg's start to (v, a) at its end
        w = v * v * frac ** (4.0 / 3.0)
        law = TimeLawSpec(j_max=j_max, accel_start=None, accel_end=a)
        return ForcedLeg(start=0.0, length=length, v0=0.0, a0=0.0, vf=v, af=a, s=s, w=w,
                         time_law=law)
    w = v * v * (1.0 - frac) ** (4.0 / 3.0)
    law = TimeLawSpec(j_max=j_max, accel_start=a, accel_end=None)
    return ForcedLeg(start=0.0, length=length, v0=v, a0=a, vf=0.0, af=0.0, s=s, w=w,
                     time_law=law)


def _spanning(forced: ForcedLeg, length: float) -> ForcedLeg:
    """``forced`` (a stop at its own length) bent to span ``length``, its state kept exactly.

    The stop's ``w = v² (1 - x)^{4/3}`` (``x = s / length``; time reversed at an end) takes a
    factor ``1 + β x`` with ``β = 4/3 (1 - length / forced.length)``: the state's speed and
    acceleration (the slope at ``x = 0``) stay exact and the jerk changes by about ``β``.
    Stretching ``s`` alone gave the law an acceleration off by ``β``, bent back to the
    state's within its first micrometres at 1.05 ``j_max``.
    """
    frac = forced.s / forced.length
    beta = (4.0 / 3.0) * (1.0 - length / forced.length)
    if forced.v0 > 0:  # from the state to rest
        w = forced.v0**2 * (1.0 - frac) ** (4.0 / 3.0) * (1.0 + beta * frac)
    else:  # from rest to the state at the end
        w = forced.vf**2 * frac ** (4.0 / 3.0) * (1.0 + beta * (1.0 - frac))
    return replace(forced, length=length, s=frac * length, w=w)


def _stops_in_closed_form(v: float, a: float, j_max: float, *, end: bool, touch: float,
                          rounded: bool, spans: tuple[float, float]) -> bool:
    """Whether a straight stretch in closed form stops at the state ``(v, a)`` on the way.

    A state whose speed falls to 0 (``v - a²/(2 j) <= 0`` at the start), one read off a
    plan's final stop (``rounded``: on the stop's curve to the law's rounding), and one
    within ``touch`` of it whose stop spans the stretch (``spans``: its length [m] and the
    relative rounding of that) do. A dip above 0 with room after it is passed exactly: a
    stop there costs a restart from rest (6 µs for a 5e-7 dip at ``j_max = 0.05``). Next to
    the stretch's end there is no such room: what a rounding of the positions leaves after
    the stop (1e-17 m) would take a rise and a fall of microseconds.
    """
    forced = _forced_stop(v, a, j_max, end=end, touch=touch, least_duration=0.0)
    if forced is None:
        return False
    length, past = spans
    return (rounded or turnaround_speed(v, -a if end else a, j_max) <= 0.0
            or abs(forced.length - length) <= past * length)


def _no_motion(forced: ForcedLeg, a_limit: float, least_duration: float) -> bool:
    """Whether the forced stop ``forced`` is rest to rounding.

    Its acceleration within ``1e-12`` of ``a_limit`` [m/s²] and its duration within ``1e-12``
    of the stretch's ``least_duration`` [s]: taking its state for rest changes neither the
    state nor the arrival beyond a rounding (and spares a law over a few hundred decades
    below a metre, which overflows). Its length is no measure: a state 1.3e-6 m/s from rest
    braking at 0.0115 m/s² (``j_max = 50``) stops within 1e-10 m, but in 0.23 ms and from an
    acceleration the plan must start with.
    """
    v, a = (forced.v0, -forced.a0) if forced.v0 > 0 else (forced.vf, forced.af)
    # The acceleration ramps linearly to 0: the stop lasts 2 v / a.
    return a <= 1e-12 * a_limit and 2.0 * v <= 1e-12 * least_duration * a


def _shifted(leg: ForcedLeg, start: float) -> ForcedLeg:
    return ForcedLeg(start=start, length=leg.length, v0=leg.v0, a0=leg.a0, vf=leg.vf,
                     af=leg.af, s=leg.s, w=leg.w, time_law=leg.time_law)


def _sub_bound(request: PlanRequest, bound: SpeedBound, lo: float, hi: float) -> SpeedBound:
    """The speed bound of the stretch ``[lo, hi]`` in the leg's own arc length."""
    del request, hi
    return bound.at_offset(lo)

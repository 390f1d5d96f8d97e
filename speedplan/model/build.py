"""From a physical request to discrete problems: legs, bounds, envelopes, grid, jerk rows.

`build_model` is the one place where limits in SI units become the rows of a
[`DiscreteProblem`][speedplan.DiscreteProblem]. A request is split into *legs* at every point
where the vehicle must be at rest: where a boundary state forces a stop on the way (a
decelerating start whose speed falls exactly to zero: the motion to that point is forced, a
`ForcedLeg`), and — with the route and cusp support — at cusps and stops. Each
`Leg` is planned on its own (`speedplan.strategy` solves it);
`explain_infeasible` restates a discrete infeasibility of its problem in speeds and
metres. This layer builds data and calls no solver.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..core.checks import FloatArray
from ..core.errors import InfeasibleError, InvalidInputError
from ..core.limits import Limits
from ..geometry import Path, SpeedBound, bound_breakpoints
from ..solve import DiscreteProblem
from ..solve.banded import MAX_RAMP_STEPS, ramp_steps
from ..solve.nojerk import max_feasible_w
from ..solve.problem import StencilRows
from .boundary import (
    STATE_JERK_ROUNDING,
    check_reachable_states,
    fastest_w,
    jerk_motion_w,
    turnaround_speed,
)
from .grid import (
    MAX_DEFAULT_NODES,
    MIN_NODES,
    adaptive_grid,
    graded_ends,
    hidden_dips,
    rest_phase_length,
    top_speed,
    uniform_grid,
)
from .refine import subdivided_grid
from .request import STATE_ROUNDING, PlanRequest, within_limit
from .standstill import calibrate_standstill_rows

__all__ = ["NO_JERK_NODES", "ForcedLeg", "Leg", "Model", "Rest", "TimeLawSpec", "build_leg",
           "build_model", "coarsenable", "coarser_leg", "explain_infeasible", "grid_anchors",
           "lateral_speed_caps", "node_bounds", "rest_points"]

#: Uniform grid of a request without jerk limit (the O(n) pass is exact on any grid).
NO_JERK_NODES = 1001
#: Rounds in which the default no-jerk grid is refined (steps / 4) where the optimum rides a
#: node bound more than `NO_JERK_BOUND_LOSS` below the bound at the node itself: the
#: minimum over the adjacent cells (`node_bounds`) costs time there, like ``O(h)``.
NO_JERK_REFINEMENTS = 1
NO_JERK_BOUND_LOSS = 1e-3
#: A decelerating boundary state whose speed falls to within this fraction of its own speed
#: (``v - a²/(2 j)``) of zero comes to rest on the way: the gain of passing through at that
#: speed is below any resolvable time, and the dip could not be gridded.
TOUCH_ZERO = 1e-6
#: ``κ``, and ``κ'`` after and before each interior node of a leg's grid.
NodeCurvature = tuple[FloatArray, FloatArray, FloatArray]
#: Newton steps for `lateral_speed_caps` (converged to rounding from its start within
#: about 40 on the sample paths) and the relative margin added to each cap, so that rounding
#: never cuts a feasible point.
CAP_NEWTON_STEPS = 60
CAP_MARGIN = 1e-9
#: ... or when passing through the dip instead of restarting from rest gains less than this
#: fraction of the move's least duration (far below the 1e-4 of the optimum plans promise).
TOUCH_TIME = 1e-6
#: Nodes of the sampled forced motion of a `ForcedLeg`.
FORCED_NODES = 401


@dataclass(frozen=True)
class TimeLawSpec:
    """How the time law interpolates the solved ``w`` (see `speedplan.timing.TimeLaw`).

    Attributes
    ----------
    j_max : float or None
        Jerk limit of a smooth standstill (the law then follows the max-jerk start and stop
        exactly at ends at rest); ``None`` for the free standstill or no jerk limit.
    accel_start, accel_end : float or None
        Prescribed accelerations at moving ends [m/s²]; ``None`` keeps the discrete slope.
    linear : bool
        ``w`` linear on each cell (no jerk nor lateral-jerk limit): the law stays on the
        chords, which the node bounds keep under the speed bound (`node_bounds`).
    """

    j_max: float | None
    accel_start: float | None
    accel_end: float | None
    linear: bool = False


@dataclass(frozen=True)
class Rest:
    """A point inside the path where the vehicle must be at rest (v = 0, a = 0).

    Attributes
    ----------
    s : float
        Position along the path [m].
    reason : str
        Why: ``"cusp"`` (the direction of travel flips), ``"stop"`` (asked for, e.g. a route
        node with a blocking action) or ``"curvature jump"`` (a G1 join with ``j_lat_max``
        set: the lateral acceleration would step).
    """

    s: float
    reason: str


@dataclass(frozen=True)
class _Ends:
    """Where a piece of the request lies and its boundary states (documented by its subclasses)."""

    start: float
    length: float
    v0: float
    a0: float
    vf: float
    af: float


@dataclass(frozen=True)
class Leg(_Ends):
    """One piece of the request, from one boundary state (or stop) to the next.

    Attributes
    ----------
    start : float
        Arc length of the leg's start along the request's path [m].
    length : float
        Leg length [m].
    v0, a0, vf, af : float
        Boundary states of the leg [m/s, m/s²].
    bound : SpeedBound
        Speed bound on the leg's own path (arc length from 0) [m²/s²].
    problem : DiscreteProblem
        Grid (from 0 to ``length``), node bounds with the boundary envelopes, rows.
    time_law : TimeLawSpec
        How to build the continuous law from its solution.
    refine : str
        Refinement mode; ``backend``: relaxation backend (from the request).
    anchors : ndarray
        Positions on the leg [m] its grids keep as nodes (joins of path pieces where the
        curvature rate jumps, with a lateral-jerk limit); empty when none.
    """

    bound: SpeedBound
    problem: DiscreteProblem
    time_law: TimeLawSpec
    limits: Limits
    refine: str = "auto"
    backend: str = "auto"
    anchors: FloatArray = field(default_factory=lambda: np.zeros(0))


@dataclass(frozen=True)
class ForcedLeg(_Ends):
    """A piece of motion with no freedom left: the max-jerk motion from a state to rest.

    From ``(v0, a0)`` with ``v0 = a0² / (2 j)`` (``a0 < 0``) every jerk-limited motion must
    apply ``+j`` until it is at rest; ``w`` is that motion sampled on ``s`` (or its time
    reversal at the end of a request, arriving at ``(vf, af)`` from rest). ``start``,
    ``length`` and the boundary states are those of `Leg`.
    """

    s: FloatArray
    w: FloatArray
    time_law: TimeLawSpec


@dataclass(frozen=True)
class Model:
    """A request modelled as legs between standstills.

    Attributes
    ----------
    request : PlanRequest
        What was asked.
    bound : SpeedBound
        ``s -> mu+(s)`` [m²/s²] along the whole path.
    legs : tuple of Leg or ForcedLeg
        In order; consecutive legs meet at rest.
    rests : tuple of Rest
        The points inside the path where the vehicle stops, in order.
    """

    request: PlanRequest
    bound: SpeedBound
    legs: tuple[Leg | ForcedLeg, ...] = field(default_factory=tuple)
    rests: tuple[Rest, ...] = ()


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
    order = {"cusp": 0, "stop": 1, "curvature jump": 2}
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
    legs: list[Leg | ForcedLeg] = []
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
                  rest_after: Rest | None) -> list[Leg | ForcedLeg]:
    """The legs of the stretch ``[lo, hi]`` between two cuts (the path's ends or rests)."""
    lim = request.limits
    (v0, a0), (vf, af) = start, end
    length = hi - lo
    if request.jerk_limited:
        try:
            check_reachable_states(v0, a0, vf, af, length, lim.v_max, lim.a_max, lim.a_decel,
                                   request.moving_state_jerk)
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
    legs: list[Leg | ForcedLeg] = []
    j_state = request.moving_state_jerk
    # A state read off a plan's final stop lies on the stop's curve up to the law's rounding.
    touch = TOUCH_ZERO if request.state_jerk is None or j_state > lim.j_max * (
        1.0 + STATE_JERK_ROUNDING) else max(TOUCH_ZERO, 2.0 * STATE_JERK_ROUNDING)
    touching = {"touch": touch, "least_duration": length / lim.v_max}
    head = _forced_stop(v0, a0, j_state, end=False, **touching) if request.jerk_limited else None
    tail = _forced_stop(vf, af, j_state, end=True, **touching) if request.jerk_limited else None
    inner_lo, inner_hi = lo, hi
    for forced in (head, tail):
        if forced is not None and length < forced.length <= length * (1.0 + STATE_ROUNDING):
            # A state on a stop's curve a rounding past the stretch (read off a plan's
            # final stop): the stop spans the stretch.
            forced = replace(forced, length=length, s=forced.s * (length / forced.length))
            head, tail = (forced, None) if forced.v0 > 0 else (None, forced)
    if head is not None:
        legs.append(_shifted(head, lo))
        inner_lo, v0, a0 = lo + head.length, 0.0, 0.0
    if tail is not None:
        inner_hi, vf, af = hi - tail.length, 0.0, 0.0
    if inner_hi - inner_lo > 1e-12 * length:
        legs.append(build_leg(request, bound, inner_lo, inner_hi, v0, a0, vf, af))
    elif head is not None and tail is not None:
        raise InfeasibleError(
            "the path is too short: both boundary states force a stop and the two stops "
            "overlap", constraint="length", s=hi)
    if tail is not None:
        legs.append(_shifted(tail, hi - tail.length))
    return legs


def build_leg(request: PlanRequest, bound: SpeedBound, lo: float, hi: float, v0: float,
              a0: float, vf: float, af: float) -> Leg:
    """The discrete problem of the stretch ``[lo, hi]`` of the request's path."""
    lim = request.limits
    length = hi - lo
    leg_bound = bound if (lo == 0.0 and hi == float(request.path.length)) else _sub_bound(
        request, bound, lo, hi)
    if request.n is not None or request.ds is not None:
        s = uniform_grid(length, n=request.n, ds=request.ds)
        if request.jerk_limited:
            v_top = top_speed(leg_bound, length, lim.v_max, v0 * v0, vf * vf)
            s = graded_ends(s, _transient(request, v0, a0, lim.a_max, length, v_top),
                            _transient(request, vf, -af, lim.a_decel, length, v_top))
        _check_moving_ends_resolved(s, lo, v0, a0, vf, af)
    elif request.jerk_limited:
        s = _default_grid(request, leg_bound, lo, hi, v0, a0, vf, af)
        leg = leg_on_grid(request, leg_bound, s, lo, v0, a0, vf, af)
        steps = ramp_steps(leg.problem)
        if steps <= MAX_RAMP_STEPS:
            return leg
        # A default grid the relaxation cannot resolve (a millimetre move whose boundary
        # transients ask for micrometre steps): coarser everywhere, in proportion.
        s = _default_grid(request, leg_bound, lo, hi, v0, a0, vf, af,
                          max(int(s.size * 0.9 * MAX_RAMP_STEPS / steps), MIN_NODES))
    else:
        s = _no_jerk_grid(request, leg_bound, length, v0, vf)
    return leg_on_grid(request, leg_bound, s, lo, v0, a0, vf, af)


def coarser_leg(request: PlanRequest, leg: Leg, factor: float) -> Leg | None:
    """``leg`` on its default grid with ``factor`` times its nodes, or ``None``.

    Every step grows in proportion (the node cap of `adaptive_grid`), so the grid
    stays smoothly graded. [`speedplan.plan`][speedplan.plan] plans a leg on such a grid when its
    relaxation backend does not converge on the default grid: on paths with slow zones both
    interior-point methods can stall on a fine default grid (a front of nearly active jerk
    rows next to a zone's edge moves one node per iteration) and converge on a coarser one.
    ``None`` for a user grid (``n`` or ``ds``: the grid is the caller's), without a jerk
    limit (no solver runs), or where the grid would not get coarser (`MIN_NODES`).

    Examples
    --------
    >>> from speedplan import Limits, Path
    >>> from speedplan.model import PlanRequest, build_model
    >>> path = Path.from_waypoints([[0, 0], [30, 0]], kind="polyline")
    >>> model = build_model(PlanRequest.create(path, Limits(2, 1, 1, 0.5)))
    >>> leg = model.legs[0]
    >>> half = coarser_leg(model.request, leg, 0.5)
    >>> bool(half.problem.n <= leg.problem.n // 2 + 1), bool(half.problem.s[-1] == 30.0)
    (True, True)
    """
    if not coarsenable(request, leg):
        return None
    nodes = max(int(leg.problem.n * factor), MIN_NODES)
    if nodes >= leg.problem.n:
        return None
    lo, hi = leg.start, leg.start + leg.length
    s = _default_grid(request, leg.bound, lo, hi, leg.v0, leg.a0, leg.vf, leg.af, nodes)
    if s.size >= leg.problem.n:
        return None
    return leg_on_grid(request, leg.bound, s, lo, leg.v0, leg.a0, leg.vf, leg.af)


def coarsenable(request: PlanRequest, leg: Leg) -> bool:
    """Whether ``leg`` is on a jerk-limited default grid above `MIN_NODES` nodes.

    The legs `coarser_leg` can rebuild coarser (without building the grid).
    """
    return (request.n is None and request.ds is None and request.jerk_limited
            and leg.problem.n > MIN_NODES)


def _default_grid(request: PlanRequest, leg_bound: SpeedBound, lo: float, hi: float,
                  v0: float, a0: float, vf: float, af: float,
                  max_nodes: int = MAX_DEFAULT_NODES) -> FloatArray:
    """The jerk-limited default grid of the leg ``[lo, hi]`` (`adaptive_grid`)."""
    lim = request.limits
    length = hi - lo
    env = _Envelopes.of(request, v0, a0, vf, af, length)
    low = [v for v in (v0, vf) if v > 0] + [
        turnaround_speed(v, a, lim.j_max) for v, a in ((v0, a0), (vf, -af))
        if v > 0 and a < 0]
    v_top = top_speed(leg_bound, length, lim.v_max, v0 * v0, vf * vf)
    return adaptive_grid(length, lambda q: env.cap(q, leg_bound(q)), a_max=lim.a_max,
                         a_decel=lim.a_decel, v_max=lim.v_max, j_max=lim.j_max,
                         w_start=v0**2, w_end=vf**2,
                         v_low=min((v for v in low if v > 0), default=None),
                         anchors=grid_anchors(request, lo, hi), max_nodes=max_nodes,
                         breakpoints=bound_breakpoints(request.path, leg_bound),
                         v_top=v_top)


def _no_jerk_grid(request: PlanRequest, bound: SpeedBound, length: float, v0: float,
                  vf: float) -> FloatArray:
    """`NO_JERK_NODES` uniform nodes, refined where the node bounds cost time.

    Where the bound falls steeply (a corner's clothoid, a zone's edge) the node bound, the
    minimum over both adjacent cells, lies well below the bound at the node; where the no-jerk
    optimum rides it, those cells and their neighbours are cut in four
    (`subdivided_grid`; the no-jerk law is linear in ``w`` per cell and needs
    no smoothness of the steps). Every other cell is kept to the last bit, so the bound
    already evaluated inside it is looked up, not evaluated again
    (`memoised`). The O(n) pass makes each round cheap;
    on the serpentine of ``benchmarks/bench_all.py`` one round takes the duration from 3.9 %
    to 1.0 % above the exact optimum.
    """
    lim = request.limits
    s = uniform_grid(length, n=NO_JERK_NODES)
    s = _cut_out_dips(s, hidden_dips(s, bound_breakpoints(request.path, bound), bound,
                                     cells=True))
    for _ in range(NO_JERK_REFINEMENTS):
        if s.size > MAX_DEFAULT_NODES:
            break
        nodes = node_bounds(bound, s)
        own = np.asarray(bound(s), dtype=np.float64)
        w_max = nodes.copy()
        w_max[0], w_max[-1] = max(w_max[0], v0 * v0), max(w_max[-1], vf * vf)
        m = s.size
        w = max_feasible_w(DiscreteProblem(
            s=s, w_max=w_max, accel=np.full(m - 1, lim.A), decel=np.full(m - 1, lim.A_decel),
            jerk=np.full(m - 2, np.inf), w_start=v0 * v0, w_end=vf * vf), pin_ends=False)
        lossy = (w >= nodes * (1.0 - 1e-9)) & (nodes < (1.0 - NO_JERK_BOUND_LOSS) * own)
        if not lossy.any():
            break
        cells = np.zeros(m - 1, dtype=bool)
        idx = np.flatnonzero(lossy)
        cells[np.clip(idx - 1, 0, m - 2)] = True
        cells[np.clip(idx, 0, m - 2)] = True
        s = subdivided_grid(s, cells, parts=4)
    return s


def _cut_out_dips(s: FloatArray, edges: FloatArray) -> FloatArray:
    """``s`` with nodes on the ``edges`` of dips of the bound and steps doubling away from them.

    A dip narrower than a step of the no-jerk grid (a hairpin's arc, a narrow zone; its
    edges from `hidden_dips`) was found by the refinements only
    where a few quarterings reach it: a 0.55 mm arc on a 1.9 km path was crossed at 18x its
    speed. With nodes on its edges the dip's cells hold its own bound; the node bound of a
    neighbour (the minimum over its cells, the dip's edge included) is the dip's too, so the
    neighbours are brought in at steps growing from the dip's width, ``w 2^k``: what the
    node bounds lose is one such step on either side.
    """
    if edges.size == 0:
        return s
    cell = np.searchsorted(s, edges) - 1
    extra = [edges]
    for c in np.unique(cell):
        lo, hi = float(edges[cell == c].min()), float(edges[cell == c].max())
        h = float(s[c + 1] - s[c])
        width = hi - lo if hi > lo else h / 1024.0
        ladder: FloatArray = width * 2.0 ** np.arange(int(np.ceil(np.log2(h / width))),
                                                     dtype=np.float64)
        extra += [lo - ladder, hi + ladder]
    new = np.unique(np.clip(np.concatenate(extra), s[0], s[-1]))
    k = np.clip(np.searchsorted(s, new), 1, s.size - 1)
    apart = np.minimum(new - s[k - 1], s[k] - new) > 1e-12 * float(s[-1] - s[0])
    out: FloatArray = np.union1d(s, new[apart])  # no cell of a few ulps
    return out


def _transient(request: PlanRequest, v: float, a: float, a_limit: float,
               length: float, v_top: float) -> float | None:
    """Length of a leg's first boundary transient (its last one: ``v = vf``, ``a = -af``).

    At a smooth standstill the first jerk phase from rest (``None`` for the paper's free
    standstill, where the acceleration may jump). A moving state: the shorter of the
    distance covered while its acceleration is brought to 0, a jerk transition
    ``v min(t_j, √(v / j))`` at the lowest speed it passes (the default grid's scale) and,
    braking, the distance ``v² / (2 |a|)`` to rest at that deceleration. The phases are
    those under ``v_top``, the leg's top speed (`top_speed`).
    """
    j = request.limits.j_max
    if v == 0.0 and a == 0.0:
        return (rest_phase_length(a_limit, v_top, j, length)
                if request.smooth_standstill else None)
    low = turnaround_speed(v, a, j) if a < 0 else v
    speed = low if low > 0 else v
    t_j = min(a_limit / j, float(np.sqrt(v_top / j)))
    scale = speed * min(t_j, float(np.sqrt(speed / j)))
    if a != 0.0:
        t = abs(a) / j
        removal = v * t + 0.5 * a * t * t - float(np.sign(a)) * j * t**3 / 6.0
        if removal > 0.0:
            scale = min(scale, removal)
    if a < 0.0:  # the first step well below the braking distance: see _check_moving_ends_resolved
        scale = min(scale, 0.5 * v * v / -a)
    return scale if scale > 0.0 else None


def leg_on_grid(request: PlanRequest, bound: SpeedBound, s: FloatArray, lo: float, v0: float,
                a0: float, vf: float, af: float) -> Leg:
    """The leg's discrete problem on the grid ``s`` (from 0 to the leg's length)."""
    lim = request.limits
    length = float(s[-1])
    env = _Envelopes.of(request, v0, a0, vf, af, length)
    w_max = env.cap(s, node_bounds(bound, s))
    w_max[0] = max(w_max[0], v0 * v0)
    w_max[-1] = max(w_max[-1], vf * vf)
    if (w_max[1:-1] <= 0).any():
        i = int(np.flatnonzero(w_max[1:-1] <= 0)[0]) + 1
        raise InvalidInputError(
            f"the speed bound is 0 at s={lo + s[i]:.6g} m inside the path ({_zero_cause(bound)}); "
            "split the path there to plan a stop"
        )
    m = s.size
    accel, decel = np.full(m - 1, lim.A), np.full(m - 1, lim.A_decel)
    curvature = None
    if np.isfinite(lim.j_lat_max):
        curvature = _node_curvature(request.path, lo, s)  # for the caps and the rows alike
        w_max[1:-1] = np.minimum(w_max[1:-1], lateral_speed_caps(
            request.path, lo, s, lim.j_lat_max, accel, decel, node_curvature=curvature))
    floor = env.floor(s)
    if floor is not None:
        # Against the bound at the nodes themselves: the node bound (its minimum over the
        # adjacent cells) is below it where the bound falls, and a state read off a plan
        # braking into a curve is that close to the slowest motion (the U-turn at t = 7.8 s).
        _check_floor(floor, np.maximum(w_max, env.cap(s, np.asarray(bound(s), dtype=np.float64))),
                     s, lo, v0, a0, vf, af)
        w_max[1:-1] = np.maximum(w_max[1:-1], floor[1:-1])
    jerk = np.full(m - 2, lim.J)
    if request.state_jerk is not None:  # the slack of marginal states, over the whole leg
        jerk[:] = 2.0 * request.state_jerk
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
        linear=not (request.jerk_limited or np.isfinite(lim.j_lat_max)),
    )
    return Leg(start=lo, length=length, v0=v0, a0=a0, vf=vf, af=af, bound=bound,
               problem=problem, time_law=law, limits=lim, refine=request.refine,
               backend=request.backend, anchors=grid_anchors(request, lo, lo + length))


def grid_anchors(request: PlanRequest, lo: float, hi: float) -> FloatArray:
    """Where a leg's default grids put nodes: joins of path pieces inside ``(lo, hi)``.

    In the leg's arc length, and only with a lateral-jerk limit: the curvature rate jumps
    there, and with a node on the join its two one-sided lateral-jerk rows hold the jump.
    """
    if not np.isfinite(request.limits.j_lat_max):
        return np.zeros(0)
    joins = request.path.offsets[1:-1]
    out: FloatArray = joins[(joins > lo) & (joins < hi)] - lo
    return out


def lateral_jerk_rows(path: Path, lo: float, s: FloatArray, j_lat_max: float, *,
                      node_curvature: NodeCurvature | None = None
                      ) -> tuple[StencilRows, ...] | None:
    """Rows ``|κ' w + κ w'| sqrt(w) <= j_lat_max`` at the nodes and the cells' midpoints.

    Lateral jerk is ``d(κ v²)/dt = sqrt(w) (κ' w + κ w')``; ``κ`` and ``κ' = dκ/ds`` are the
    path's at ``lo + s``. Two kinds of rows, each a second-order discretisation at its point:

    * **at each interior node**, ``w'`` the three-point first difference of the (non-uniform)
      grid, exact for quadratic ``w``. At a node on a join of pieces ``κ'`` jumps (a clothoid
      onto an arc): the lateral jerk takes both one-sided values there, so a second family
      holds the rows with the rate before the join (elsewhere it has none);
    * **at each cell's midpoint**, ``w' = (w_{i+1} - w_i) / h_i`` and ``w = (w_i + w_{i+1}) / 2``
      with ``κ, κ'`` at the midpoint, times ``sqrt(w)`` at either end of the cell (two families:
      the row is held with both, which bounds it with ``sqrt`` of the midpoint's ``w``).

    The node rows alone cannot see the node-to-node (odd/even) zigzag of ``w``: the centred
    difference of an alternating sequence is 0, so only the tangential jerk rows limit it and
    the discrete optimum drives it to the jerk cap (the jerk chatters between ``±j_max`` from
    node to node in curves, for a gain of ~1e-5 of the duration). The one-sided difference of
    the midpoint rows sees it. Held at twice as many points, the rows also bound the lateral
    jerk of the continuous law between the nodes (measured: 3.9 % above the limit with the
    node rows alone on a random G2 path, 0.4 % with both).
    """
    if not np.isfinite(j_lat_max):
        return None
    kappa, after, before = node_curvature or _node_curvature(path, lo, s)
    h = np.diff(s)
    h0, h1 = h[:-1], h[1:]
    first = np.column_stack((-h1 / (h0 * (h0 + h1)), (h1 - h0) / (h0 * h1),
                             h0 / (h1 * (h0 + h1))))
    bound = np.full(s.size - 2, float(j_lat_max))
    families = []
    for rate, rows in ((after, bound), (before, np.where(before != after, bound, np.inf))):
        if not np.isfinite(rows).any():
            continue
        coef = kappa[:, None] * first
        coef[:, 1] += rate
        families.append(StencilRows(coef=coef, bound=rows))
    families.extend(_midpoint_rows(path, lo, s, bound))
    return tuple(families)


def _node_curvature(path: Path, lo: float, s: FloatArray) -> NodeCurvature:
    """``κ``, and ``κ'`` after and before each interior node (they differ on piece joins)."""
    q = lo + s[1:-1]
    kappa = np.asarray(path.curvature(q), dtype=np.float64)
    after = np.asarray(path.curvature_rate(q), dtype=np.float64)
    before = after.copy()
    joins = path.offsets[1:-1]
    if joins.size:
        k = np.searchsorted(joins, q)  # nearest join to each node
        for cand in (np.clip(k - 1, 0, joins.size - 1), np.clip(k, 0, joins.size - 1)):
            on = np.abs(joins[cand] - q) <= 1e-12 * max(float(path.length), 1.0)
            for i in np.flatnonzero(on):
                piece = path.pieces[int(cand[i])]  # the piece ending at that join
                before[i] = float(piece.curvature_rate(np.array(piece.length)))
    return kappa, after, before


def lateral_speed_caps(path: Path, lo: float, s: FloatArray, j_lat_max: float,
                       accel: FloatArray, decel: FloatArray, *,
                       node_curvature: NodeCurvature | None = None) -> FloatArray:
    """Upper bounds on interior ``w`` that the lateral-jerk and acceleration rows imply.

    The node row ``|κ' w_i + κ w'_i| sqrt(w_i) <= j_lat_max`` (`lateral_jerk_rows`) has
    ``w'_i`` a convex combination of the slopes of the two adjacent cells, each within
    ``[-D, A]`` by the acceleration rows. So ``|κ' w_i + κ w'_i| >= |κ'| w_i - |κ| M_i`` with
    ``M_i`` the larger braking bound ``D`` of the two cells where ``κ' κ > 0`` (braking eases
    a curvature that grows in magnitude), the larger ``A`` elsewhere, and every feasible ``w``
    has ``sqrt(w_i) (|κ'| w_i - |κ| M_i) <= j_lat_max``: ``w_i <= x²``, with ``x`` the positive
    root of ``|κ'| x³ - |κ| M_i x - j_lat_max``. The bound removes no feasible point of the
    discrete problem (its optimum is unchanged), but the relaxation can no longer drive
    ``w`` past it and pay for the lateral-jerk excess at one node: on comfort plans the
    certified gap falls from a few per cent to about 0.1 % (``benchmarks/bench_comfort.py``).
    ``inf`` where the curvature rate is 0.
    """
    kappa, after, before = node_curvature or _node_curvature(path, lo, s)
    caps = np.full(s.size - 2, np.inf)
    for rate in (after, before):
        eases = rate * kappa > 0
        m = np.where(eases, np.maximum(decel[:-1], decel[1:]),
                     np.maximum(accel[:-1], accel[1:]))
        a = np.abs(rate)
        on = a > 0
        if not on.any():
            continue
        a, km = a[on], np.abs(kappa[on]) * m[on]
        # f(x) = a x³ - km x - B is convex and increasing right of its root: Newton from an
        # upper bound of the root converges from the right, monotonically.
        x = np.maximum(np.cbrt(2.0 * j_lat_max / a), np.sqrt(2.0 * km / a))
        for _ in range(CAP_NEWTON_STEPS):
            x = x - (a * x**3 - km * x - j_lat_max) / (3.0 * a * x * x - km)
        caps[on] = np.minimum(caps[on], x * x * (1.0 + CAP_MARGIN))
    return caps


def _midpoint_rows(path: Path, lo: float, s: FloatArray, bound: FloatArray
                   ) -> tuple[StencilRows, StencilRows]:
    """The midpoint rows of `lateral_jerk_rows`, with ``sqrt(w)`` of either end of a cell.

    The first family's row at node ``i`` is the cell ``(i, i+1)``'s, the second's the cell
    ``(i-1, i)``'s.
    """
    h = np.diff(s)
    mid = lo + 0.5 * (s[:-1] + s[1:])
    kappa = path.curvature(mid)
    rate = path.curvature_rate(mid)
    left = 0.5 * rate - kappa / h  # weights of w_i and w_{i+1} in κ' w_mid + κ w'_mid
    right = 0.5 * rate + kappa / h
    zero = np.zeros(s.size - 2)
    ahead = StencilRows(coef=np.column_stack((zero, left[1:], right[1:])), bound=bound)
    behind = StencilRows(coef=np.column_stack((left[:-1], right[:-1], zero)), bound=bound)
    return ahead, behind


def _check_moving_ends_resolved(s: FloatArray, lo: float, v0: float, a0: float, vf: float,
                                af: float) -> None:
    """A user grid must let the speed stay positive over the first (last) half cell.

    The grading of user grids (`_transient`, `graded_ends`) makes the end
    steps shorter than this; what remains refused is a transient below the finest step.

    The time law keeps the prescribed acceleration at a moving end; a braking start
    (accelerating arrival) then loses ``|a| h`` of ``w`` over the half cell, so a step
    ``h >= v² / |a|`` would bring the vehicle to rest inside the cell: that transient is
    shorter than the grid can resolve.
    """
    for name, v, slowing, h, where in (("start", v0, -a0, s[1] - s[0], lo),
                                       ("end", vf, af, s[-1] - s[-2], lo + s[-1])):
        if v > 0 and slowing > 0 and h >= 0.5 * v * v / slowing:
            h_max = 0.5 * v * v / slowing
            n_min = int(np.ceil(float(s[-1]) / h_max)) + 1
            state = (f"v0={v:.6g} m/s, a0={-slowing:.6g} m/s²" if name == "start"
                     else f"vf={v:.6g} m/s, af={slowing:.6g} m/s²")
            raise InvalidInputError(
                f"the grid step {h:.3g} m is too coarse for the {name} state {state} at "
                f"s={where:.6g} m: its transient lasts less than one step (steps below "
                f"{h_max:.3g} m resolve it); use the default grid (n=None and ds=None), "
                f"n >= {n_min} or ds < {h_max:.3g}"
            )


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
    ends = np.sqrt(bound(np.array([0.0, length])))
    v0, vf = (within_limit(name, v, float(b), "m/s", f"the speed bound at s={where:.6g} m "
                           "(v_max, lateral acceleration, a zone or v_limit)")
              for name, v, b, where in (("v0", request.v0, ends[0], 0.0),
                                        ("vf", request.vf, ends[1], length)))
    if (v0, vf) == (request.v0, request.vf):
        return request
    return replace(request, v0=v0, vf=vf)


def _check_floor(floor: FloatArray, w_max: FloatArray, s: FloatArray, lo: float, v0: float,
                 a0: float, vf: float, af: float) -> None:
    """The slowest motion from the start (into the end) must stay under the speed bound."""
    over = floor[1:-1] > w_max[1:-1] * (1 + 1e-9) + 1e-300
    if over.any():
        i = int(np.flatnonzero(over)[0]) + 1
        near_start = s[i] < 0.5 * s[-1]
        state = (f"v0={v0:.6g} m/s, a0={a0:.6g} m/s²" if near_start else
                 f"vf={vf:.6g} m/s, af={af:.6g} m/s²")
        verb = "cannot slow down to" if near_start else "cannot come from"
        raise InfeasibleError(
            f"from {state} a jerk-limited vehicle {verb} the speed bound "
            f"{np.sqrt(w_max[i]):.6g} m/s at s={lo + s[i]:.6g} m: even its slowest motion is "
            f"at {np.sqrt(floor[i]):.6g} m/s there (j_max, a_decel, a_max)",
            constraint="speed_bound", s=float(lo + s[i]),
        )


@dataclass(frozen=True)
class _Envelopes:
    """Jerk-limited envelopes of the motions leaving the start state and reaching the end."""

    limits: Limits
    smooth: bool
    jerk_limited: bool
    v0: float
    a0: float
    vf: float
    af: float
    length: float
    in_distance: bool = False
    state_j: float | None = None  # the jerk of a moving state's envelopes (default j_max)

    @classmethod
    def of(cls, request: PlanRequest, v0: float, a0: float, vf: float, af: float,
           length: float) -> _Envelopes:
        """The envelopes of one leg of ``request`` between the given states."""
        return cls(request.limits, request.smooth_standstill, request.jerk_limited, v0, a0,
                   vf, af, length, in_distance=request.reach == "distance",
                   state_j=request.moving_state_jerk)

    def cap(self, s: FloatArray, w: FloatArray) -> FloatArray:
        """``w`` capped by the largest ``w`` reachable from (v0, a0) and reaching (vf, af).

        At rest the cap is the max-jerk start only for a smooth standstill (the paper's free
        standstill lets the acceleration jump there); a moving state is always capped: by
        the max-jerk motion, or with ``in_distance`` by the envelope in distance
        (`fastest_w`), which is above it where the vehicle
        could brake to rest and start again (``PlanRequest.reach``).
        """
        lim = self.limits
        if not self.jerk_limited:
            return w
        if self.smooth or self.v0 > 0:
            w = np.minimum(w, self._fastest(s, self.v0, self.a0, lim.a_max, lim.a_decel,
                                            moving=self.v0 > 0))
        if self.smooth or self.vf > 0:
            w = np.minimum(w, self._fastest(self.length - s, self.vf, -self.af, lim.a_decel,
                                            lim.a_max, moving=self.vf > 0))
        return w

    def _fastest(self, d: FloatArray, v: float, a: float, a_limit: float,
                 a_brake: float, *, moving: bool) -> FloatArray:
        j = self.state_j if moving and self.state_j is not None else self.limits.j_max
        if self.in_distance:
            return fastest_w(d, v, a, j, a_limit, a_brake)
        return jerk_motion_w(d, v, a, j, a_limit)

    def floor(self, s: FloatArray) -> FloatArray | None:
        """The slowest motion leaving a moving start (and arriving at a moving end)."""
        lim = self.limits
        if not self.jerk_limited or (self.v0 == 0.0 and self.vf == 0.0):
            return None
        lo = np.zeros_like(s)
        j = lim.j_max if self.state_j is None else self.state_j
        if self.v0 > 0:
            lo = np.maximum(lo, jerk_motion_w(s, self.v0, self.a0, -j, -lim.a_decel))
        if self.vf > 0:
            lo = np.maximum(lo, jerk_motion_w(self.length - s, self.vf, -self.af, -j,
                                              -lim.a_max))
        return lo


def _forced_stop(v: float, a: float, j_max: float, *, end: bool, touch: float,
                 least_duration: float) -> ForcedLeg | None:
    """The forced motion to rest when a decelerating start (accelerating end) touches zero.

    ``j_max``: the jerk the state may use (``PlanRequest.moving_state_jerk``). It touches
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


def _shifted(leg: ForcedLeg, start: float) -> ForcedLeg:
    return ForcedLeg(start=start, length=leg.length, v0=leg.v0, a0=leg.a0, vf=leg.vf,
                     af=leg.af, s=leg.s, w=leg.w, time_law=leg.time_law)


def _sub_bound(request: PlanRequest, bound: SpeedBound, lo: float, hi: float) -> SpeedBound:
    """The speed bound of the stretch ``[lo, hi]`` in the leg's own arc length."""
    del request, hi
    return bound.at_offset(lo)


def node_bounds(bound: Any, s: FloatArray, per_interval: int = 8) -> FloatArray:
    """Bound at each node: the minimum of ``bound`` over its two adjacent intervals.

    The discrete problem sees the bound only at nodes; taking the minimum over the neighbouring
    intervals keeps the interpolated speed under a bound that drops between nodes (a zone
    entry, a curvature peak) at an ``O(h)`` cost where the bound is smooth. Interpolated
    linearly (the law without a jerk limit) ``w`` stays under the larger node value of each
    cell, so under the bound; the jerk-limited law bends away from the chords only by its
    curvature, ``O(j h²)`` (`speedplan.timing.law`).
    """
    frac = np.arange(per_interval) / per_interval
    # Every node once (the start of its interval, and the end of the grid), then the points
    # inside each interval: one call to the bound.
    sub = np.append((s[:-1, None] + np.diff(s)[:, None] * frac[None, :]).ravel(), s[-1])
    sub[::per_interval] = s
    val = np.asarray(bound(sub), dtype=np.float64)
    w = val[::per_interval].copy()
    interval_min = np.minimum(val[:-1].reshape(-1, per_interval).min(axis=1), w[1:])
    w[:-1] = np.minimum(w[:-1], interval_min)
    w[1:] = np.minimum(w[1:], interval_min)
    return w


def explain_infeasible(exc: InfeasibleError, leg: Leg) -> InfeasibleError:
    """Restate a discrete infeasibility in speeds and metres (positions along the path)."""
    lim = leg.limits
    if exc.s is None:
        return InfeasibleError(
            f"no speed law meets the request between s={leg.start:.6g} m and "
            f"s={leg.start + leg.length:.6g} m: {exc}", constraint=exc.constraint)
    where = leg.start + exc.s
    i = int(np.argmin(np.abs(leg.problem.s - exc.s)))
    v_there = float(np.sqrt(leg.problem.w_max[i]))
    if exc.constraint == "decel":
        msg = (f"cannot brake from v0={leg.v0:.6g} m/s to {v_there:.6g} m/s (the speed bound "
               f"at s={where:.4g} m) under a_decel={lim.a_decel:.6g} m/s²")
    elif exc.constraint == "accel":
        msg = (f"cannot reach vf={leg.vf:.6g} m/s at the end from {v_there:.6g} m/s (the "
               f"speed bound at s={where:.4g} m) under a_max={lim.a_max:.6g} m/s²")
    elif exc.constraint == "jerk":
        msg = (f"cannot slow down in time for the speed bound {v_there:.6g} m/s at "
               f"s={where:.4g} m from v0={leg.v0:.6g} m/s, a0={leg.a0:.6g} m/s² under "
               f"j_max={lim.j_max:.6g} m/s³ and a_decel={lim.a_decel:.6g} m/s²")
    elif exc.constraint == "w_max":
        msg = (f"no motion passes s={where:.4g} m: the speed bound there ({v_there:.3g} m/s) "
               f"and the acceleration bounds leave no positive speed inside the leg; split "
               f"the path there to plan a stop, or raise the bound")
    else:
        msg = str(exc)
    return InfeasibleError(msg, constraint=exc.constraint, s=where)

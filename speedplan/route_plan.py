"""plan_route(): a route (e.g. a VDA 5050 order) -> one minimum-time motion with node times."""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Sequence
from concurrent.futures import Executor
from typing import TypedDict, Unpack

import numpy as np

from .batch import PlanJob, plan_many
from .core.checks import as_scalar
from .core.errors import (
    InfeasibleError,
    InvalidInputError,
    PlanTimeout,
    SolverError,
    SpeedplanError,
)
from .core.limits import Limits
from .core.numerics import wrap_angle
from .core.options import Backend, Refine, Standstill
from .geometry import SpanLimit, SpeedZone
from .model import PlanRequest
from .plan import plan_request
from .route import THETA_TOLERANCE, Route, RouteProfile
from .route.profile import RouteTurn
from .strategy import Budget
from .timing import SpeedProfile
from .timing.rotation import Turn

__all__ = ["RouteOptions", "plan_route", "plan_route_update", "route_jobs", "route_turns"]

#: plan() options that plan_route() sets itself from the route.
_FROM_ROUTE = ("v0", "a0", "vf", "af", "stops", "spans", "v_limit")


class _LegOptions(TypedDict, total=False):
    n: int | None
    ds: float | None
    zones: Sequence[SpeedZone] | None
    refine: Refine
    standstill: Standstill
    backend: Backend


class RouteOptions(_LegOptions, total=False):
    """The [`speedplan.plan`][speedplan.plan] keywords of a route's legs, all optional.

    ``n``, ``ds``, ``zones``, ``refine``, ``standstill``, ``backend`` and ``time_limit``, as
    for `speedplan.plan`; stops, spans and boundary states come from the route itself.
    """

    time_limit: float | None


def route_jobs(route: Route, limits: Limits, *, start_s: float = 0.0, v0: float = 0.0,
               a0: float = 0.0, **plan_options: Unpack[RouteOptions]
               ) -> tuple[list[PlanJob], list[float]]:
    """The `speedplan.plan_many` jobs of a route's stop-to-stop legs, and where each starts.

    Leg ``j`` runs from ``max(stop_s[j], start_s)`` to ``stop_s[j + 1]`` along
    `Route.path` (legs wholly behind ``start_s`` are dropped); the first starts at
    ``(v0, a0)``, every other from rest; each ends at rest. The edges' ``v_max`` and
    ``yaw_rate_max`` become [`SpanLimit`][speedplan.SpanLimit] over their part of the leg.
    Each job is a validated [`PlanJob`][speedplan.batch.PlanJob] (``time_limit``, if given,
    is each leg's own); a leg's invalid argument raises
    [`InvalidInputError`][speedplan.InvalidInputError] naming the leg.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan import Limits
    >>> from speedplan.geometry import Line, Path
    >>> from speedplan.route import Route, RouteEdge, RouteNode
    >>> nodes = [RouteNode("A", 0, (0.0, 0.0)), RouteNode("B", 2, (4.0, 0.0), stop=True),
    ...          RouteNode("C", 4, (9.0, 0.0))]
    >>> edges = [RouteEdge("AB", 1, "A", "B", Path.from_segments([Line(4.0)]), v_max=1.0),
    ...          RouteEdge("BC", 3, "B", "C", Path.from_segments([Line(5.0)], start=(4, 0)))]
    >>> jobs, starts = route_jobs(Route(nodes, edges), Limits(2, 1, 1, 0.5))
    >>> starts, [job.request.path.length for job in jobs], jobs[0].request.spans
    ([0.0, 4.0], [4.0, 5.0], (SpanLimit(start=0.0, end=4.0, v_max=1.0, yaw_rate_max=None),))
    """
    if not isinstance(route, Route):
        raise InvalidInputError(
            f"`route` must be a speedplan.route.Route; got {type(route).__name__} (read an "
            "order with Route.from_vda5050 or speedplan.io.read_route)"
        )
    given = sorted(k for k in plan_options if k in _FROM_ROUTE)
    if given:
        raise InvalidInputError(
            f"plan_route sets {', '.join(map(repr, given))} from the route (its stops and edge "
            "limits, the start state v0/a0); pass zones for regions with their own limit"
        )
    length = route.length
    start = as_scalar("start_s", start_s, nonnegative=True)
    if not start < length:
        raise InvalidInputError(
            f"`start_s`={start!r} m must lie before the end of the route ({length:.9g} m)"
        )
    time_limit = plan_options.pop("time_limit", None)
    leg_options: _LegOptions = plan_options
    stops = route.stop_s
    path = route.path
    jobs: list[PlanJob] = []
    starts: list[float] = []
    for j in range(stops.size - 1):
        lo, hi = max(float(stops[j]), start), float(stops[j + 1])
        if hi - lo <= 1e-9 * length:
            continue
        first = not jobs
        try:
            request = PlanRequest.create(
                path.sub(lo, hi), limits, v0=v0 if first else 0.0, a0=a0 if first else 0.0,
                spans=_edge_spans(route, lo, hi), **leg_options)
            jobs.append(PlanJob(request, time_limit))
        except SpeedplanError as exc:
            raise _on_leg(exc, lo, hi) from exc
        starts.append(lo)
    return jobs, starts


def _edge_spans(route: Route, lo: float, hi: float) -> list[SpanLimit]:
    """The limited edges' stretches inside ``[lo, hi]``, in the leg's own arc length."""
    out = []
    for edge, (a, b) in zip(route.base_edges, route.edge_spans, strict=True):
        if edge.v_max is None and edge.yaw_rate_max is None:
            continue
        a, b = max(a, lo), min(b, hi)
        if b - a > 1e-12 * max(hi - lo, 1.0):
            out.append(SpanLimit(a - lo, min(b - lo, hi - lo), v_max=edge.v_max,
                                 yaw_rate_max=edge.yaw_rate_max))
    return out


def route_turns(route: Route, limits: Limits, *, start_s: float = 0.0, v0: float = 0.0,
                heading0: float | None = None) -> tuple[RouteTurn, ...]:
    """The turns on the spot of a route from ``start_s`` on (see `plan_route`).

    Each step of [`Route.turn_headings`][speedplan.Route] on a node at or after ``start_s`` is one
    rest-to-rest [`Turn`][speedplan.timing.rotation.Turn] by the shorter way round, within
    `Route.turn_rate_limit` and ``limits.yaw_rate_max``, ``limits.yaw_acc_max`` and
    ``limits.yaw_jerk_max``.
    ``heading0`` [rad] replaces the arrival heading where the motion starts.

    Examples
    --------
    A corner that may not be cut (no allowed deviation) at (10, 0), 0.3 rad/s on both edges:

    >>> import numpy as np
    >>> from speedplan import Limits
    >>> from speedplan.geometry import Line, Path
    >>> from speedplan.route import Route, RouteEdge, RouteNode
    >>> nodes = [RouteNode("n0", 0, (0.0, 0.0)), RouteNode("n1", 2, (10.0, 0.0)),
    ...          RouteNode("n2", 4, (10.0, 10.0))]
    >>> edges = [RouteEdge("e0", 1, "n0", "n1", Path.from_segments([Line(10.0)]),
    ...                    yaw_rate_max=0.3),
    ...          RouteEdge("e1", 3, "n1", "n2", Path.from_segments(
    ...              [Line(10.0)], start=(10, 0), heading=np.pi / 2), yaw_rate_max=0.3)]
    >>> [(t.node, round(t.turn.angle, 6), round(t.duration, 3))
    ...  for t in route_turns(Route(nodes, edges), Limits(2, 1, 1, 0.5))]
    [(1, 1.570796, 5.536)]
    """
    start = float(start_s)
    tol = 1e-9 * max(route.length, 1.0)
    out: list[RouteTurn] = []
    at_node = False
    for k, heads in enumerate(route.turn_headings):
        s = float(route.node_s[k])
        if s < start - tol:
            continue
        here = abs(s - start) <= tol
        at_node = at_node or here
        if here and heading0 is not None and heads:
            heads = route.node_headings(k, float(heading0))
        out += _turns(heads, k, s, route.turn_rate_limit(k), limits)
    if heading0 is not None and not at_node:  # between nodes: the vehicle faces the path
        on_path = float(route.path.heading(start_s))
        off = abs(float(wrap_angle(on_path - heading0)))
        if off > THETA_TOLERANCE:
            if v0 > 0:
                raise InvalidInputError(
                    f"`heading0`={heading0!r} rad is {off:.3g} rad off the path's heading "
                    f"{on_path:.6g} rad at `start_s`={start_s!r} m; a vehicle moving along the "
                    "path faces its tangent (or the opposite on an edge driven backwards)")
            edge = route.base_edges[int(np.clip(np.searchsorted(route.node_s, start_s) - 1,
                                                0, len(route.base_edges) - 1))]
            rate = np.inf if edge.yaw_rate_max is None else edge.yaw_rate_max
            out = _turns((float(heading0), on_path), -1, float(start_s), rate, limits) + out
    return tuple(out)


def _turns(heads: tuple[float, ...], node: int, s: float, rate: float,
           limits: Limits) -> list[RouteTurn]:
    rate = min(rate, limits.yaw_rate_max)
    return [RouteTurn(node, s, Turn(a, float(wrap_angle(b - a)), rate, limits.yaw_acc_max,
                                    limits.yaw_jerk_max), rate)
            for a, b in itertools.pairwise(heads)]


def plan_route(route: Route, limits: Limits, *, start_s: float = 0.0, v0: float = 0.0,
               a0: float = 0.0, heading0: float | None = None,
               executor: Executor | None = None,
               **plan_options: Unpack[RouteOptions]) -> RouteProfile:
    """Plan the minimum-time motion along a route's released base.

    The vehicle stops (v = 0, a = 0) at every `Route.stop_s` — the nodes with a
    blocking action, changes of driving direction, heading jumps it cannot round, node
    orientations (``theta``) the path does not meet — and at the end of the released base,
    and drives through every other node without slowing more than its limits ask. Where its
    heading must change on a node it turns on the spot ([`Route.turn_headings`][speedplan.Route]): a
    minimum-time rest-to-rest rotation within the edges' ``maxRotationSpeed``,
    ``limits.yaw_rate_max``, ``limits.yaw_acc_max`` and ``limits.yaw_jerk_max``, the shorter
    way round; the turns'
    time is part of `RouteProfile.node_times` (arrival), ``node_leave_times`` and the
    sampled trajectory. Each stop-to-stop leg is one [`speedplan.plan`][speedplan.plan] (one
    discrete problem, certified on its own); the legs are independent, so ``executor``
    can plan them in parallel ([`speedplan.plan_many`][speedplan.plan_many]).

    Parameters
    ----------
    route : Route
        E.g. ``Route.from_vda5050(order)`` or [`speedplan.io.read_route`][speedplan.io.read_route].
    limits : Limits
        The vehicle's limits; each edge's ``v_max`` and ``yaw_rate_max`` apply on top over
        the edge.
    start_s : float
        Where the vehicle is along the route [m] (an order update received while driving:
        the new plan continues from there); default the start.
    v0, a0 : float
        Its speed [m/s] and acceleration [m/s²] there.
    heading0 : float, optional
        Its heading [rad] there. Default: on the first node its ``theta`` (else the first
        edge's heading), elsewhere the route's. Standing on a node, the vehicle turns from it
        to the node's ``theta`` and the next edge's heading; between nodes it must face the
        path (or stand, ``v0 = 0``, and turn onto it).
    executor : concurrent.futures.Executor, optional
        Plan the legs on it (``plan_many``); default: one after the other in this process.
    **plan_options
        Other [`speedplan.plan`][speedplan.plan] keywords (``n``, ``ds``, ``zones``, ``refine``,
        ``standstill``, ``backend``, ``time_limit``); stops, spans and boundary states come
        from the route. ``time_limit`` [s] bounds the whole route when the legs are planned
        here (each leg gets what the ones before it left), each leg with an ``executor``
        (they run in parallel).

    Returns
    -------
    RouteProfile
        ``duration``, ``node_times``, ``legs``, ``sample(dt)`` (a
        [`RouteTrajectory`][speedplan.route.RouteTrajectory] with an ``edge`` column), ``verify()``.

    Raises
    ------
    InvalidInputError
        Bad arguments (``start_s`` beyond the end, an option the route sets).
    InfeasibleError
        A leg cannot be driven (the message says which constraint and where, ``s`` along
        the leg; the route position is its start plus that).

    Examples
    --------
    One 12 m edge limited to 1 m/s (a VDA 5050 order reads into the same
    [`Route`][speedplan.Route], see [`from_vda5050`][speedplan.Route.from_vda5050]):

    >>> from speedplan import Limits, plan_route
    >>> from speedplan.geometry import Line, Path
    >>> from speedplan.route import Route, RouteEdge, RouteNode
    >>> edge = RouteEdge("AB", 1, "A", "B", Path.from_segments([Line(12.0)]), v_max=1.0)
    >>> route = Route([RouteNode("A", 0, (0.0, 0.0)), RouteNode("B", 2, (12.0, 0.0))], [edge])
    >>> profile = plan_route(route, Limits(2, 1, 1, 0.5))

    At the edge's 1 m/s the jerk-limited start (and stop) takes ``2 sqrt(v/j) = 2.828`` s over
    1.414 m; 9.172 m of cruise remain: 14.828 s in all.

    >>> profile.node_times.round(3).tolist(), profile.status
    ([0.0, 14.828], 'optimal')
    """
    time_limit = plan_options.pop("time_limit", None)
    budget = Budget.of(time_limit)
    jobs, starts = route_jobs(route, limits, start_s=start_s, v0=v0, a0=a0, **plan_options)
    if heading0 is not None:
        heading0 = as_scalar("heading0", heading0)
    turns = route_turns(route, limits, start_s=start_s, v0=v0, heading0=heading0)
    if executor is None:
        legs: list[SpeedProfile] = []
        for job, lo in zip(jobs, starts, strict=True):
            try:
                legs.append(plan_request(job.request, time_limit=_leg_time(budget, legs, jobs)))
            except SpeedplanError as exc:
                raise _on_leg(exc, lo, lo + job.request.path.length) from exc
    else:
        results = plan_many(jobs, executor, time_limit=budget.time_limit)
        legs = []
        for result, lo, job in zip(results, starts, jobs, strict=True):
            if result.error is not None:
                if isinstance(result.error, SpeedplanError):
                    raise _on_leg(result.error, lo, lo + job.request.path.length) \
                        from result.error
                raise result.error
            assert result.profile is not None
            legs.append(result.profile)
    return RouteProfile(route=route, legs=tuple(legs), leg_starts=tuple(starts),
                        start_s=float(start_s), turns=turns)


def plan_route_update(profile: RouteProfile, route: Route, t: float, limits: Limits | None = None,
                      *, executor: Executor | None = None,
                      **plan_options: Unpack[RouteOptions]) -> RouteProfile:
    """Plan an order update from where the vehicle is at time ``t`` of the current plan.

    ``route`` is the update (VDA 5050: the same ``orderId``, a larger ``orderUpdateId``), whose
    first node is a node of the current base — the last node of the old base, with the
    horizon released and the route extended; an update that repeats nodes the vehicle has
    passed is joined the same way, provided its geometry passes where the vehicle is. The update
    is joined to the part of the current route before that node, and planned from the
    vehicle's state on ``profile`` at ``t``: position, speed, acceleration and heading.
    The new motion continues the old one (the same position, ``v`` and ``a`` at the switch);
    its time 0 is ``t`` of the old plan.

    Where the vehicle is already past the start of a corner the update would round on the
    joining node, it is too late to cut it: the node is then passed as a square corner (the
    vehicle stops on it and turns).

    Parameters
    ----------
    profile : RouteProfile
        The plan being driven (from [`plan_route`][speedplan.plan_route] or this function).
    route : Route
        The order update.
    t : float
        When the update takes over [s on ``profile``'s clock], not during a turn on the spot.
    limits : Limits, optional
        The vehicle's limits; default those ``profile`` was planned with.
    executor, **plan_options
        As for [`plan_route`][speedplan.plan_route].

    Returns
    -------
    RouteProfile
        Over the joined route, from the vehicle's position (its `RouteProfile.start_s`).

    Raises
    ------
    InvalidInputError
        Another order, an ``orderUpdateId`` that is not larger, an update that does not start
        on a node of the current base, a ``t`` during a turn on the spot, or an update whose
        geometry does not pass the vehicle's position.

    Examples
    --------
    A base ``A - B`` (horizon ``B - C``), updated 3 s in with the horizon released: the
    vehicle no longer stops on B.

    >>> from dataclasses import replace
    >>> from speedplan import Limits, plan_route
    >>> from speedplan.geometry import Line, Path
    >>> from speedplan.route import Route, RouteEdge, RouteNode
    >>> a, b = RouteNode("A", 0, (0.0, 0.0)), RouteNode("B", 2, (8.0, 0.0))
    >>> ab = RouteEdge("AB", 1, "A", "B", Path.from_segments([Line(8.0)]))
    >>> def bc(released):
    ...     return RouteEdge("BC", 3, "B", "C", Path.from_segments([Line(8.0)], start=(8, 0)),
    ...                      released=released)
    >>> c = RouteNode("C", 4, (16.0, 0.0))
    >>> old = plan_route(Route([a, b, replace(c, released=False)], [ab, bc(False)],
    ...                        order_id="o", order_update_id=0), Limits(2, 1, 1, 0.5))
    >>> update = Route([b, c], [bc(True)], order_id="o", order_update_id=1)
    >>> new = plan_route_update(old, update, 3.0)
    >>> before, after = old.at(3.0), new.at(0.0)
    >>> bool(abs(before.s[0] - after.s[0]) < 1e-9 and abs(before.v[0] - after.v[0]) < 1e-6)
    True
    >>> len(new.route.stop_s), round(new.route.length, 6)
    (2, 16.0)
    """
    if not isinstance(profile, RouteProfile):
        raise InvalidInputError(
            f"`profile` must be a RouteProfile (from plan_route); got {type(profile).__name__}")
    if not isinstance(route, Route):
        raise InvalidInputError(f"`route` must be a speedplan.Route; got {type(route).__name__}")
    old = profile.route
    if old.order_id is not None and route.order_id is not None \
            and route.order_id != old.order_id:
        raise InvalidInputError(
            f"`route` is order {route.order_id!r}, the plan drives {old.order_id!r}; an order "
            "update keeps the orderId (plan a new order with plan_route)")
    if old.order_update_id is not None and route.order_update_id is not None \
            and not route.order_update_id > old.order_update_id:
        raise InvalidInputError(
            f"`route.order_update_id` {route.order_update_id} must be larger than the current "
            f"plan's {old.order_update_id}")
    when = as_scalar("t", t, nonnegative=True)
    for turn, start in zip(profile.turns, profile.turn_times, strict=True):
        if start < when < start + turn.duration:
            raise InvalidInputError(
                f"at `t`={when!r} s the vehicle is turning on the spot on node "
                f"{old.base_nodes[turn.node].node_id!r} until t={start + turn.duration:.6g} s; "
                "take the update over before or after the turn")
    first = route.nodes[0]
    k = next((k for k, n in enumerate(old.base_nodes)
              if n.sequence_id == first.sequence_id and n.node_id == first.node_id), None)
    if k is None:
        raise InvalidInputError(
            f"`route` starts on node {first.node_id!r} (sequenceId {first.sequence_id}), which "
            "is not a node of the current base; an order update starts on one (VDA 5050: the "
            "last node of the previous base)")
    state = profile.at(np.array([when]))
    s_old = float(state.s[0])
    joined = _joined(old, route, k)
    if not _same_place(old, joined, s_old):  # too late to round the joining node
        node = route.nodes[0]
        square = dataclasses.replace(node, allowed_deviation_xy=0.0, deviation_ellipse=None)
        joined = _joined(old, dataclasses.replace(route, nodes=(square, *route.nodes[1:])), k)
        if not _same_place(old, joined, s_old):
            raise InvalidInputError(
                f"the update's geometry does not pass the vehicle's position at s={s_old:.6g} m "
                "of the current route; an update keeps the base the vehicle is on")
    return plan_route(joined, profile.legs[0].limits if limits is None else limits,
                      start_s=s_old, v0=max(float(state.v[0]), 0.0), a0=float(state.a[0]),
                      heading0=float(state.heading[0]), executor=executor, **plan_options)


def _joined(old: Route, update: Route, k: int) -> Route:
    """The current route's nodes and edges before its base node ``k``, then the update."""
    return Route(old.nodes[:k] + update.nodes, old.edges[:k] + update.edges,
                 order_id=update.order_id, order_update_id=update.order_update_id,
                 version=update.version, notes=update.notes)


def _same_place(old: Route, new: Route, s: float) -> bool:
    """Whether both routes put the vehicle at ``s``, and just behind it, on the same points.

    Two points fix position and heading (the heading at a node itself belongs to the edge
    after it).
    """
    if s > new.length:
        return False
    at = np.array([max(s - 1e-3, 0.0), s])
    gap = np.asarray(old.path.point(at)) - np.asarray(new.path.point(at))
    return bool(np.max(np.hypot(gap[:, 0], gap[:, 1])) <= 1e-6)


def _leg_time(budget: Budget, legs: Sequence[SpeedProfile], jobs: Sequence[PlanJob]
              ) -> float | None:
    """The time the next leg may take: what the legs before it left of the route's limit."""
    if budget.time_limit is None:
        return None
    if budget.expired():
        raise PlanTimeout(
            f"time_limit={budget.time_limit:.6g} s ran out after {len(legs)} of the route's "
            f"{len(jobs)} legs; pass a larger time_limit", time_limit=budget.time_limit)
    return budget.remaining()


def _on_leg(exc: SpeedplanError, lo: float, hi: float) -> SpeedplanError:
    """The leg's error, saying which leg, with ``s`` along the route."""
    msg = f"on the leg from s={lo:.6g} m to s={hi:.6g} m of the route: {exc}"
    if isinstance(exc, InfeasibleError):
        return InfeasibleError(msg, constraint=exc.constraint,
                               s=None if exc.s is None else lo + exc.s)
    if isinstance(exc, SolverError):
        return SolverError(msg, backend=exc.backend, status=exc.status)
    if isinstance(exc, InvalidInputError):
        return InvalidInputError(msg)
    if isinstance(exc, PlanTimeout):
        return PlanTimeout(msg, time_limit=exc.time_limit, attempts=exc.attempts)
    return SpeedplanError(msg)

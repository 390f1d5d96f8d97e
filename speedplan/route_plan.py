"""plan_route(): a route (e.g. a VDA 5050 order) -> one minimum-time motion with node times."""

from __future__ import annotations

from concurrent.futures import Executor
from typing import Any

from .batch import plan_many
from .core.checks import as_scalar
from .core.errors import InfeasibleError, InvalidInputError, SolverError, SpeedplanError
from .core.limits import Limits
from .geometry import SpanLimit
from .plan import plan
from .route import Route, RouteProfile

__all__ = ["plan_route", "route_jobs"]

#: plan() options that plan_route() sets itself from the route.
_FROM_ROUTE = ("v0", "a0", "vf", "af", "stops", "spans", "v_limit")


def route_jobs(route: Route, limits: Limits, *, start_s: float = 0.0, v0: float = 0.0,
               a0: float = 0.0, **plan_options: Any) -> tuple[list[dict[str, Any]], list[float]]:
    """The `speedplan.plan` jobs of a route's stop-to-stop legs, and where each starts.

    Leg ``j`` runs from ``max(stop_s[j], start_s)`` to ``stop_s[j + 1]`` along
    `Route.path` (legs wholly behind ``start_s`` are dropped); the first starts at
    ``(v0, a0)``, every other from rest; each ends at rest. The edges' ``v_max`` and
    ``yaw_rate_max`` become [`SpanLimit`][speedplan.SpanLimit] over their part of the leg.

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
    >>> starts, [job["path"].length for job in jobs], jobs[0]["spans"]
    ([0.0, 4.0], [4.0, 5.0], [SpanLimit(start=0.0, end=4.0, v_max=1.0, yaw_rate_max=None)])
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
    stops = route.stop_s
    path = route.path
    jobs: list[dict[str, Any]] = []
    starts: list[float] = []
    for j in range(stops.size - 1):
        lo, hi = max(float(stops[j]), start), float(stops[j + 1])
        if hi - lo <= 1e-9 * length:
            continue
        first = not jobs
        jobs.append({
            "path": path.sub(lo, hi), "limits": limits,
            "v0": v0 if first else 0.0, "a0": a0 if first else 0.0,
            "spans": _edge_spans(route, lo, hi), **plan_options,
        })
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


def plan_route(route: Route, limits: Limits, *, start_s: float = 0.0, v0: float = 0.0,
               a0: float = 0.0, executor: Executor | None = None,
               **plan_options: Any) -> RouteProfile:
    """Plan the minimum-time motion along a route's released base.

    The vehicle stops (v = 0, a = 0) at every `Route.stop_s` — the nodes with a
    blocking action, changes of driving direction, heading jumps it cannot round — and at
    the end of the released base, and drives through every other node without slowing
    more than its limits ask. Each stop-to-stop leg is one [`speedplan.plan`][speedplan.plan] (one
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
    executor : concurrent.futures.Executor, optional
        Plan the legs on it (``plan_many``); default: one after the other in this process.
    **plan_options
        Other [`speedplan.plan`][speedplan.plan] keywords (``n``, ``ds``, ``zones``, ``refine``,
        ``standstill``, ``backend``); stops, spans and boundary states come from the route.

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
    jobs, starts = route_jobs(route, limits, start_s=start_s, v0=v0, a0=a0, **plan_options)
    if executor is None:
        legs = []
        for job, lo in zip(jobs, starts, strict=True):
            options = {k: v for k, v in job.items() if k not in ("path", "limits")}
            try:
                legs.append(plan(job["path"], job["limits"], **options))
            except SpeedplanError as exc:
                raise _on_leg(exc, lo, job) from exc
    else:
        results = plan_many(jobs, executor)
        legs = []
        for result, lo, job in zip(results, starts, jobs, strict=True):
            if result.error is not None:
                if isinstance(result.error, SpeedplanError):
                    raise _on_leg(result.error, lo, job) from result.error
                raise result.error
            assert result.profile is not None
            legs.append(result.profile)
    return RouteProfile(route=route, legs=tuple(legs), leg_starts=tuple(starts),
                        start_s=float(start_s))


def _on_leg(exc: SpeedplanError, lo: float, job: dict[str, Any]) -> SpeedplanError:
    """The leg's error, saying which leg, with ``s`` along the route."""
    hi = lo + float(job["path"].length)
    msg = f"on the leg from s={lo:.6g} m to s={hi:.6g} m of the route: {exc}"
    if isinstance(exc, InfeasibleError):
        return InfeasibleError(msg, constraint=exc.constraint,
                               s=None if exc.s is None else lo + exc.s)
    if isinstance(exc, SolverError):
        return SolverError(msg, backend=exc.backend, status=exc.status)
    if isinstance(exc, InvalidInputError):
        return InvalidInputError(msg)
    return SpeedplanError(msg)

"""plan(): validate the request -> model it -> solve each leg -> time law -> verified profile.

Each stage's fallbacks are the attempts of `speedplan.strategy`, run under the
caller's ``time_limit``.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

from .core.errors import SpeedplanWarning
from .core.limits import Limits
from .core.options import Backend, Refine, Standstill, VLimit
from .geometry import Path, SpanLimit, SpeedBound, SpeedZone
from .model import Model, PlanRequest
from .model.request import STANDSTILL_MODES
from .strategy import (
    COARSER_GRIDS,
    MAX_REFINEMENTS,
    REFINE_FACTORS,
    Budget,
    Record,
    model_request,
    refine_factor,
    solve_legs,
    verified_profile,
)
from .timing import SpeedProfile

# SpeedBound is re-exported so that pickles made when it lived here still load; the
# strategy's constants and refine_factor, for code that imported them from here.
__all__ = ["COARSER_GRIDS", "MAX_REFINEMENTS", "REFINE_FACTORS", "STANDSTILL_MODES",
           "SpeedBound", "plan", "plan_request", "refine_factor"]


def plan(
    path: Path,
    limits: Limits,
    *,
    n: int | None = None,
    ds: float | None = None,
    v0: float = 0.0,
    a0: float = 0.0,
    vf: float = 0.0,
    af: float = 0.0,
    zones: Sequence[SpeedZone] | None = None,
    v_limit: VLimit | None = None,
    refine: Refine = "auto",
    standstill: Standstill = "smooth",
    backend: Backend = "auto",
    stops: Sequence[float] | None = None,
    spans: Sequence[SpanLimit] | None = None,
    time_limit: float | None = None,
) -> SpeedProfile:
    """Plan the minimum-time speed law along ``path`` under ``limits``.

    Parameters
    ----------
    path : Path
        Arc-length parametrised path.
    limits : Limits
        Speed, acceleration, braking, lateral acceleration and jerk limits (SI).
    n, ds : int or float, optional
        Uniform grid with ``n`` nodes or step at most ``ds`` [m] (per leg), graded finer
        at a leg's ends where its step is longer than 1/20 of the boundary transient (the
        first jerk phase from rest, a moving state's change of acceleration;
        `graded_ends`): the law would exceed the limits there and
        the grid be refined after a first solve. By default the
        grid is adaptive and smoothly graded: ~80 nodes per jerk transition, coarse in long
        cruises; where the relaxation backend does not converge on it (seen on paths with
        slow zones), the leg is planned on the same grid with a half, a quarter, an eighth
        of its nodes (`COARSER_GRIDS`), then on these grids with the other backend
        too, before a [`SolverError`][speedplan.SolverError] is raised (the attempts of
        `speedplan.strategy`). A grid given with ``n`` or ``ds`` is never changed this
        way.
    v0, a0 : float
        Speed [m/s] and acceleration [m/s²] at the start (default: at rest).
    vf, af : float
        Speed and acceleration at the end (default: at rest).
    zones : sequence of SpeedZone, optional
        Polygons with their own speed limit.
    v_limit : tuple (s, v), optional
        Per-position speed limit along the path: knots ``s`` [m] (strictly increasing) and
        speeds ``v`` [m/s] (>= 0), linear in between (see `speedplan.speed_bounds`).
    refine : {"auto", "always", "never"}
        IPOPT refinement when the relaxation is not exact (see `solve_discrete`).
    standstill : {"smooth", "free"}
        ``"smooth"`` (default): acceleration 0 at a standstill, jerk-limited from the first
        instant. ``"free"``: the paper's model, where acceleration may jump *at a standstill*
        (moving boundary states stay jerk-limited).
    backend : {"auto", "clarabel", "banded"}
        Relaxation backend (see [`speedplan.solve_discrete`][speedplan.solve_discrete]).
    stops : sequence of float, optional
        Positions [m] strictly inside the path where the vehicle must come to rest
        (v = 0, a = 0), e.g. a route node with a blocking action. The vehicle also stops at
        every cusp of the path ([`Path.cusps`][speedplan.Path.cusps], where it reverses) and, when
        ``limits.j_lat_max`` is set, at every curvature jump (`Path.curvature_jumps`;
        a [`SpeedplanWarning`][speedplan.SpeedplanWarning] says where — G2 paths, the default of
        [`Path.from_waypoints`][speedplan.Path.from_waypoints], have none).
    spans : sequence of SpanLimit, optional
        Speed and yaw-rate limits over stretches of the path (e.g. a route's edges).
    time_limit : float, optional
        Seconds the plan may take (wall clock, from the call). The strategy's attempts
        (`speedplan.strategy`) run in order while time is left; the first verified plan
        is returned, and [`PlanTimeout`][speedplan.PlanTimeout] is raised if the limit passes
        before one is found. The limit is checked before each attempt: an attempt already
        running is not interrupted, so the answer can come later than the limit by one
        attempt (see docs/failure-modes.md). Default: no limit.

    Returns
    -------
    SpeedProfile
        The speed law, its certificate, and ``sample(dt)`` for a time trajectory. Its
        continuous trajectory is checked against every limit (`SpeedProfile.verify`);
        where it exceeds a tolerance the grid is refined there, up to
        `MAX_REFINEMENTS` times; if it still does, the status is
        ``"limits_exceeded"`` and a [`LimitWarning`][speedplan.LimitWarning] is issued.
        `SpeedProfile.attempts` records which attempt answered for each leg and why
        the others failed.

    Raises
    ------
    InvalidInputError
        Malformed arguments, a path shorter than ``1e-9 v_max² / a_max`` (nearly coincident
        waypoints), or boundary speeds beyond the speed bound.
    InfeasibleError
        No jerk-limited motion meets the boundary states (the message says which state, which
        limit and where, ``s`` in metres). A moving state that ``j_max (1 +
        STATE_JERK_ROUNDING)`` (1e-4) reaches, such as a state read off a plan, is planned
        with that jerk, silently, as is one read off the last jerk phase of a plan's stop
        that ``j_max (1 + STATE_JERK_LAW_ROUNDING)`` (3e-3) reaches (in its stretch up to
        the next stop only); one that ``j_max (1 + STATE_JERK_SLACK)`` (2 %) reaches,
        with up to that jerk while its acceleration is brought to 0 (``j_max`` after) and a
        [`SpeedplanWarning`][speedplan.SpeedplanWarning] (`speedplan.strategy.model_request`).
    SolverError
        Neither relaxation backend converged on the leg's grid (nor, on a default grid, on
        the coarser ones), and no feasible speed law could be produced.
    PlanTimeout
        ``time_limit`` passed before a verified plan was found; the message names every
        attempt made and why each did not answer.

    Examples
    --------
    A 30 m straight move from rest to rest; the jerk-limited optimum takes 19 s:

    >>> from speedplan import Limits, Path, plan
    >>> path = Path.from_waypoints([[0, 0], [30, 0]], kind="polyline")
    >>> prof = plan(path, Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
    >>> round(prof.duration, 3), prof.status
    (19.0, 'optimal')
    >>> traj = prof.sample(dt=0.01)
    >>> bool(traj.v.max() <= 2.0 * 1.001)
    True

    Which attempt of the strategy answered: a straight move between states at rest is
    planned in closed form (its exact optimum, no grid), a curved one on the default grid:

    >>> [(a.name, a.outcome) for a in prof.attempts]
    [('model', 'answered'), ('closed_form', 'answered')]
    >>> corner = Path.from_waypoints([[0, 0], [30, 0], [30, 10]])
    >>> [(a.name, a.outcome) for a in plan(corner, Limits(2, 1, 1, 0.5)).attempts]
    [('model', 'answered'), ('default_grid', 'answered')]
    """
    budget = Budget.of(time_limit)
    request = PlanRequest.create(
        path, limits, n=n, ds=ds, v0=v0, a0=a0, vf=vf, af=af, zones=zones, v_limit=v_limit,
        refine=refine, standstill=standstill, backend=backend, stops=stops, spans=spans,
    )
    return plan_request(request, budget=budget)


def plan_request(request: PlanRequest, *, time_limit: float | None = None,
                 budget: Budget | None = None) -> SpeedProfile:
    """[`plan`][speedplan.plan] for an already validated `PlanRequest`.

    ``budget`` (a `Budget` already running) takes the place of
    ``time_limit``.
    """
    record = Record(budget if budget is not None else Budget.of(time_limit))
    modelled, model = model_request(request, record)
    _warn_curvature_jumps(model)
    legs, coarsened = solve_legs(modelled, model, record)
    return verified_profile(modelled, model, legs, coarsened, record)


def _warn_curvature_jumps(model: Model) -> None:
    jumps = [r.s for r in model.rests if r.reason == "curvature jump"]
    if jumps:
        shown = ", ".join(f"{s:.6g}" for s in jumps[:5]) + (", ..." if len(jumps) > 5 else "")
        warnings.warn(
            f"the path's curvature jumps at s = {shown} m: with j_lat_max set the lateral "
            "acceleration cannot step, so the vehicle stops there; use a curvature-continuous "
            "path (Path.from_waypoints with the default kind='g2') to drive through",
            SpeedplanWarning, stacklevel=4,
        )

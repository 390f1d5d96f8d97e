"""plan(): validate the request -> model it -> solve each leg -> time law -> verified profile."""

from __future__ import annotations

import contextlib
import time
import warnings
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from .core.errors import InfeasibleError, LimitWarning, SolverError, SpeedplanWarning
from .core.limits import Limits
from .geometry import Path, SpanLimit, SpeedBound, SpeedZone
from .model import ForcedLeg, Leg, Model, PlanRequest, build_model
from .model.boundary import STATE_JERK_SLACK, state_jerk
from .model.build import coarsenable, coarser_leg, leg_on_grid
from .model.refine import refined_grid
from .model.request import STANDSTILL_MODES
from .solve import DiscreteSolution
from .timing import TOLERANCES, LegResult, SpeedProfile, Verification, law_for

# SpeedBound is re-exported so that pickles made when it lived here still load.
__all__ = ["COARSER_GRIDS", "MAX_REFINEMENTS", "REFINE_FACTORS", "STANDSTILL_MODES",
           "SpeedBound", "plan", "plan_request", "refine_factor"]

#: What the reachability checks of boundary states name when they refuse one.
STATE_CONSTRAINTS = ("jerk", "v_max", "length", "speed_bound")
#: Rounds of local grid refinement where the continuous law exceeds a tolerance.
MAX_REFINEMENTS = 3
#: Bounds on the factor a refinement round multiplies the flagged steps by (finer in one
#: round grades the grid so steeply that the banded kernel loses accuracy, measured).
REFINE_FACTORS = (1 / 4, 1 / 2)
#: Fractions of its nodes a jerk-limited default grid is rebuilt with, in turn, when the
#: relaxation backend does not converge on it (`coarser_leg`).
COARSER_GRIDS = (1 / 2, 1 / 4, 1 / 8)


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
    v_limit: Any = None,
    refine: str = "auto",
    standstill: str = "smooth",
    backend: str = "auto",
    stops: Sequence[float] | None = None,
    spans: Sequence[SpanLimit] | None = None,
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
        too, before a [`SolverError`][speedplan.SolverError] is raised. A grid given with ``n`` or
        ``ds`` is never changed this way.
    v0, a0 : float
        Speed [m/s] and acceleration [m/s²] at the start (default: at rest).
    vf, af : float
        Speed and acceleration at the end (default: at rest).
    zones : sequence of SpeedZone, optional
        Polygons with their own speed limit.
    v_limit : tuple (s, v), optional
        Per-position speed limit along the path (see `speedplan.speed_bounds`).
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

    Returns
    -------
    SpeedProfile
        The speed law, its certificate, and ``sample(dt)`` for a time trajectory. Its
        continuous trajectory is checked against every limit (`SpeedProfile.verify`);
        where it exceeds a tolerance the grid is refined there, up to
        `MAX_REFINEMENTS` times; if it still does, the status is
        ``"limits_exceeded"`` and a [`LimitWarning`][speedplan.LimitWarning] is issued.

    Raises
    ------
    InvalidInputError
        Malformed arguments, a path shorter than ``1e-9 v_max² / a_max`` (nearly coincident
        waypoints), or boundary speeds beyond the speed bound.
    InfeasibleError
        No jerk-limited motion meets the boundary states (the message says which state, which
        limit and where, ``s`` in metres). Moving states that ``j_max`` misses by a hair but
        ``j_max (1 + STATE_JERK_SLACK)`` (2 %) reaches are planned with that jerk instead, with
        a [`SpeedplanWarning`][speedplan.SpeedplanWarning].
    SolverError
        Neither relaxation backend converged on the leg's grid (nor, on a default grid, on
        the coarser ones), and no feasible speed law could be produced.

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
    """
    request = PlanRequest.create(
        path, limits, n=n, ds=ds, v0=v0, a0=a0, vf=vf, af=af, zones=zones, v_limit=v_limit,
        refine=refine, standstill=standstill, backend=backend, stops=stops, spans=spans,
    )
    return plan_request(request)


def plan_request(request: PlanRequest) -> SpeedProfile:
    """[`plan`][speedplan.plan] for an already validated `PlanRequest`."""
    modelled, model = _model_reaching_the_states(request)
    jumps = [r.s for r in model.rests if r.reason == "curvature jump"]
    if jumps:
        shown = ", ".join(f"{s:.6g}" for s in jumps[:5]) + (", ..." if len(jumps) > 5 else "")
        warnings.warn(
            f"the path's curvature jumps at s = {shown} m: with j_lat_max set the lateral "
            "acceleration cannot step, so the vehicle stops there; use a curvature-continuous "
            "path (Path.from_waypoints with the default kind='g2') to drive through",
            SpeedplanWarning, stacklevel=3,
        )
    first = [_solve_default(modelled, leg) for leg in model.legs]
    legs = [result for result, _ in first]
    profile = SpeedProfile(path=request.path, limits=request.limits, legs=tuple(legs),
                           speed_bound=model.bound, request=request)
    # Each leg is checked once per law it gets: the final verification merges these checks
    # (what profile.verify() computes) instead of checking every leg again.
    leg_checks = [profile.check_leg(i) for i in range(len(legs))]
    stuck: set[int] = set()  # legs whose refined law did not arrive: retrying repeats it
    for _ in range(MAX_REFINEMENTS):
        if all(c.verification.ok for c in leg_checks):
            break
        changed = []
        for i, (leg, leg_check) in enumerate(zip(model.legs, leg_checks, strict=True)):
            if not leg_check.verification.ok and isinstance(leg, Leg) and i not in stuck:
                grid = refined_grid(legs[i].s, leg_check.knots, leg_check.excess,
                                    leg.anchors, refine_factor(leg_check.verification))
                finer = leg_on_grid(modelled, leg.bound, grid, leg.start, leg.v0, leg.a0,
                                    leg.vf, leg.af)
                try:
                    legs[i] = _solve(finer)
                except SolverError:  # keep the verified law; its excess is reported below
                    stuck.add(i)
                    continue
                changed.append(i)
        profile = replace(profile, legs=tuple(legs))
        for i in changed:
            leg_checks[i] = profile.check_leg(i)
    # A leg planned on a coarser grid (its backend had stalled on the default one) whose law
    # still exceeds a limit: the default grid with the other backend as well, if that law
    # passes (seen on a zone path whose eighth grid left six steps for the last rest phase).
    for i, (leg, (_, coarsened)) in enumerate(zip(model.legs, first, strict=True)):
        if coarsened and not leg_checks[i].verification.ok:
            with contextlib.suppress(SolverError):
                trial = replace(profile, legs=(*legs[:i], _solve(leg), *legs[i + 1:]))
                trial_check = trial.check_leg(i)
                if trial_check.verification.ok:
                    profile, legs, leg_checks[i] = trial, list(trial.legs), trial_check
    check = Verification.merged([c.verification for c in leg_checks])
    if not check.ok:
        worst = ", ".join(f"{k} {r:.3f}× at s={check.where.get(k, float('nan')):.4g} m"
                          for k, r in check.violations.items())
        warnings.warn(
            f"the planned trajectory exceeds limits beyond tolerance ({worst} of the limit) "
            f"even after {MAX_REFINEMENTS} local refinements; status 'limits_exceeded' — see "
            "profile.verification, or plan with a finer grid (n or ds)",
            LimitWarning, stacklevel=3,
        )
    # The bound's memo (every position evaluated while planning) stays with the plan, not
    # with the profile a caller keeps.
    return replace(profile, verification=check, limits_exceeded=not check.ok,
                   speed_bound=replace(model.bound, memo=None))


def _model_reaching_the_states(request: PlanRequest) -> tuple[PlanRequest, Model]:
    """The request's model, else with exact reach envelopes, else with a hair more jerk.

    Moving boundary states are capped by the max-jerk motion (``reach="max_jerk"``), which
    keeps the relaxation exact but misses feasible motions whose speed first dips: if it
    refuses the states, the exact envelope in distance (``reach="distance"``) decides.

    Marginal states: moving boundary states just outside what ``j_max`` reaches are planned
    with ``j_max (1 + STATE_JERK_SLACK)`` (with a warning). A state read off a planned
    trajectory (whose jerk may exceed ``j_max`` within its 5 % tolerance, e.g. for an order
    update) or measured on the vehicle can lie a hair outside the set a jerk-limited motion
    reaches; refusing it would strand the vehicle. The plan is still verified against the
    requested limits.
    """
    moving = any(x != 0.0 for x in (request.v0, request.a0, request.vf, request.af))
    try:
        return request, build_model(request)
    except InfeasibleError as exc:
        if not (moving and request.jerk_limited and exc.constraint in STATE_CONSTRAINTS):
            raise
        refusal = exc
    exact = replace(request, reach="distance")
    with contextlib.suppress(InfeasibleError):
        return exact, build_model(exact)
    lim = request.limits
    looser_jerk = replace(lim, j_max=state_jerk(lim.j_max))
    for looser in (replace(request, limits=looser_jerk), replace(exact, limits=looser_jerk)):
        with contextlib.suppress(InfeasibleError):
            model = build_model(looser)
            break
    else:
        raise refusal from None
    warnings.warn(
        f"the boundary states are reachable only with {STATE_JERK_SLACK:.0%} more jerk than "
        f"j_max={lim.j_max:.6g} m/s³ ({refusal}); planned with j_max={looser.limits.j_max:.6g} "
        "m/s³, within the jerk tolerance", SpeedplanWarning, stacklevel=4,
    )
    return looser, model


def refine_factor(check: Verification) -> float:
    """What to multiply the flagged steps by so that the worst excess falls to half its tolerance.

    Near a violation the excess of a ratio beyond 1 shrinks about like the grid step (a
    first-order discretisation error), so a ratio ``1 + e`` asks for the steps times
    ``tol / (2 e)``; the factor is kept within `REFINE_FACTORS`.

    Examples
    --------
    >>> from speedplan.timing import Verification
    >>> refine_factor(Verification(maxima={}, ratios={"lateral_jerk": 1.4}, where={}))
    0.25
    >>> round(refine_factor(Verification(maxima={}, ratios={"jerk": 1.06, "speed": 1.0},
    ...                                  where={})), 6)
    0.416667
    """
    wanted = [0.5 * TOLERANCES[name] / (ratio - 1.0)
              for name, ratio in check.ratios.items() if ratio > 1.0 + TOLERANCES[name]]
    lo, hi = REFINE_FACTORS
    return float(np.clip(min(wanted, default=hi), lo, hi))


def _solve_default(request: PlanRequest, leg: Leg | ForcedLeg) -> tuple[LegResult, bool]:
    """`_solve`, on coarser default grids if the backend does not converge.

    Measured on slow-zone paths (``benchmarks/fuzz_zones.py``): both interior-point methods
    can stall on a fine default grid and converge on one with a half to an eighth of its
    nodes, in well under a second, where the other backend takes 10 s to 7 min on the fine
    grid to fail or to return a relaxation that needs IPOPT. So the backend alone is tried
    on the default grid and on the coarser ones (`COARSER_GRIDS`), and only then the
    same grids with the other backend as well; the law is verified and refined locally like
    any other. A user grid is never changed. Returns the result and whether it came from a
    coarser grid before the other backend was tried on the default one.
    """
    if not (isinstance(leg, Leg) and coarsenable(request, leg)):
        return _solve(leg), False
    with contextlib.suppress(SolverError):
        return _solve(leg, fallback=False), False
    grids: list[Leg] = [leg]  # built only now: most default grids solve at once
    for factor in COARSER_GRIDS:
        coarser = coarser_leg(request, leg, factor)
        if coarser is None or coarser.problem.n >= grids[-1].problem.n:
            break
        grids.append(coarser)
    for fallback in (False, True):
        for grid in grids if fallback else grids[1:]:
            try:
                return _solve(grid, fallback=fallback), not fallback
            except SolverError as exc:
                if fallback and grid is leg:
                    failure = exc
    raise failure


def _solve(leg: Leg | ForcedLeg, *, fallback: bool = True) -> LegResult:
    """Solve one leg and build its law (``fallback``: see `Leg.solve`)."""
    if isinstance(leg, ForcedLeg):
        t0 = time.perf_counter()
        law = law_for(leg.s, leg.w, leg.time_law)
        duration = law.duration
        solution = DiscreteSolution(
            w=leg.w, objective=duration, lower_bound=duration, gap=0.0, exact=True,
            exact_a_priori=True, jerk_violation=0.0, refined=False, status="optimal",
            solve_time=time.perf_counter() - t0, backend="forced",
        )
        return LegResult(start=leg.start, s=leg.s, solution=solution, law=law)
    solution = leg.solve(fallback=fallback)
    law = law_for(leg.problem.s, solution.w, leg.time_law)
    if not np.isfinite(law.duration):  # never hand out a trajectory that does not arrive
        raise SolverError(
            f"the speed law between s={leg.start:.6g} m and s={leg.start + leg.length:.6g} m "
            "comes to rest before its end (the grid does not resolve a boundary transient); "
            "plan with the default grid (n=None, ds=None)")
    return LegResult(start=leg.start, s=leg.problem.s, solution=solution, law=law)

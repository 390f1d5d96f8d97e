"""The planning strategy behind `speedplan.plan`: ordered attempts, a budget, a record.

A plan is one pass through a fixed chain of named attempts (`ATTEMPTS`), each tried
only when the ones before it did not answer:

* **model** (once per request): ``"model"``, the request as asked (moving boundary states
  capped by the max-jerk motion); ``"exact_reach"``, the exact reach envelope in distance,
  when the first refuses moving states that a motion whose speed first dips reaches;
  ``"state_rounding"`` and ``"exact_reach_state_rounding"``, both again with ``j_max (1 +
  STATE_JERK_ROUNDING)`` (a state read off a plan; silent); ``"law_rounding"`` and
  ``"exact_reach_law_rounding"`` with ``j_max (1 + STATE_JERK_LAW_ROUNDING)`` (a state read
  off a plan's approach to a stop, whose law rides the max-jerk stop within its own rounding;
  silent, in the state's stretch only); then
  ``"jerk_slack"`` and ``"exact_reach_jerk_slack"``, for moving states just outside what
  ``j_max`` reaches: up to ``j_max (1 + STATE_JERK_SLACK)`` while such a state's
  acceleration is brought to 0 (a `TurnLeg`), ``j_max`` elsewhere; then
  ``"jerk_slack_whole_move"`` and ``"exact_reach_jerk_slack_whole_move"`` with that jerk
  over the whole move, where a turn does not fit (both with a
  [`SpeedplanWarning`][speedplan.SpeedplanWarning]).
* **solve** (per leg): ``"forced_motion"`` for a leg with no freedom left; ``"closed_form"``
  for a straight leg whose minimum-time motion is known exactly (`StraightLeg`); ``"given_grid"``
  for the caller's grid (``n`` or ``ds``: both relaxation backends, never another grid);
  otherwise ``"default_grid"`` with the request's backend (for a leg that starts or ends at a
  moving state, this and the attempts below refine without IPOPT unless the leg has
  friction-ellipse rows), then, for such a leg whose refinement found no feasible point,
  ``"state_rounding_on_grid"``: the same grid with ``j_max (1 + STATE_JERK_PINNED)`` in its
  rows (a state on the edge of what ``j_max`` reaches further on leaves the problem no
  interior; silent), then ``"coarser_grid_1/2"``,
  ``"coarser_grid_1/4"``, ``"coarser_grid_1/8"`` (`COARSER_GRIDS`) with it, then
  ``"other_backend"`` on each of these grids in turn.
* **verify** (per leg whose continuous law exceeds a tolerance): up to
  `MAX_REFINEMENTS` rounds of ``"local_refinement"`` of the grid where it does, then,
  for a leg answered on a coarser grid, ``"default_grid_other_backend"``. These improve a
  law the plan already has, so without ``time_limit`` each leg's have a time of their own
  (`refinement_seconds`: as long as the leg's first answer took, at least
  `MIN_REFINEMENT_SECONDS`; with it, what the limit leaves): an attempt that
  would not end within it (it takes about as long as the leg's last solve) is not started
  (recorded as ``"skipped"``), and a solver that can stop stops at its end; the plan then
  keeps the law it has and reports any excess (``limits_exceeded``).

`Budget` holds the caller's ``time_limit``: it is checked before every attempt, and
an attempt the budget no longer covers is not started. The record of every attempt (which
answered, why the others failed or were replaced, what each cost) is kept on the profile,
[`attempts`][speedplan.SpeedProfile]. When the budget runs out before a verified plan,
[`PlanTimeout`][speedplan.PlanTimeout] names what was tried; a profile whose law has not passed
its check is never returned.
"""

from __future__ import annotations

import contextlib
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import partial
from typing import TypeVar

import numpy as np

from .core.attempts import Attempt, AttemptOutcome, describe_attempts
from .core.checks import FloatArray, as_scalar
from .core.deadline import deadline
from .core.errors import (
    InfeasibleError,
    InvalidInputError,
    LimitWarning,
    PlanTimeout,
    SolverError,
    SpeedplanWarning,
)
from .core.options import RelaxationBackend
from .model import ForcedLeg, Leg, Model, ModelLeg, PlanRequest, StraightLeg, TurnLeg, build_model
from .model.boundary import (
    STATE_JERK_LAW_ROUNDING,
    STATE_JERK_PINNED,
    STATE_JERK_ROUNDING,
    STATE_JERK_SLACK,
    state_jerk,
)
from .model.build import leg_on_grid
from .model.grid import MIN_NODES, refined_grid
from .model.leg_grid import default_grid
from .model.legs import explain_infeasible
from .solve import DiscreteSolution, solve_problem
from .timing import (
    TOLERANCES,
    LegResult,
    MotionLaw,
    SpeedLaw,
    SpeedProfile,
    Verification,
    law_for,
)

__all__ = ["ATTEMPTS", "COARSER_GRIDS", "EXCESS_GROWTH", "MAX_REFINEMENTS",
           "MIN_REFINEMENT_SECONDS", "REFINE_FACTORS", "STATE_CONSTRAINTS", "Budget", "Record",
           "coarsenable", "coarser_leg", "excess", "model_request", "refine_factor",
           "refinement_seconds", "solve_leg", "solve_legs", "verified_profile"]

#: What the reachability checks of boundary states name when they refuse one.
STATE_CONSTRAINTS = ("jerk", "v_max", "length", "speed_bound")
#: Rounds of local grid refinement where the continuous law exceeds a tolerance.
MAX_REFINEMENTS = 3
#: The least time the attempts that improve a leg's first answer may take [s]
#: (`refinement_seconds`).
MIN_REFINEMENT_SECONDS = 1.0
#: A refined law whose worst excess (in tolerances, `excess`) is more than this many times
#: that of the law it refines is dropped, and the leg is not refined again.
EXCESS_GROWTH = 4.0
#: Bounds on the factor a refinement round multiplies the flagged steps by (finer in one
#: round grades the grid so steeply that the banded kernel loses accuracy, measured).
REFINE_FACTORS = (1 / 4, 1 / 2)
#: Fractions of its nodes a jerk-limited default grid is rebuilt with, in turn, when the
#: relaxation backend does not converge on it (`coarser_leg`).
COARSER_GRIDS = (1 / 2, 1 / 4, 1 / 8)

#: Every attempt's name, in the order the strategy tries them (see the module docstring).
ATTEMPTS: tuple[str, ...] = (
    "model", "exact_reach", "state_rounding", "exact_reach_state_rounding", "law_rounding",
    "exact_reach_law_rounding", "jerk_slack", "exact_reach_jerk_slack", "jerk_slack_whole_move",
    "exact_reach_jerk_slack_whole_move",
    "forced_motion", "closed_form", "given_grid", "default_grid", "state_rounding_on_grid",
    *(f"coarser_grid_1/{round(1 / f)}" for f in COARSER_GRIDS),
    "other_backend", "local_refinement", "default_grid_other_backend",
)

T = TypeVar("T")


@dataclass
class Budget:
    """The time a plan may take: ``time_limit`` seconds from ``start`` (``None``: no limit).

    Examples
    --------
    >>> Budget(None).remaining()
    inf
    >>> Budget(0.0).expired()
    True
    """

    time_limit: float | None
    start: float = field(default_factory=time.perf_counter)

    @classmethod
    def of(cls, time_limit: float | None) -> Budget:
        """A budget starting now; ``time_limit`` checked (a positive number of seconds)."""
        if time_limit is None:
            return cls(None)
        return cls(as_scalar("time_limit", time_limit, positive=True))

    def elapsed(self) -> float:
        """Seconds since the budget started."""
        return time.perf_counter() - self.start

    def remaining(self) -> float:
        """Seconds left (``inf`` without a limit)."""
        if self.time_limit is None:
            return float("inf")
        return self.time_limit - self.elapsed()

    def expired(self) -> bool:
        """Whether the limit has passed."""
        return self.remaining() <= 0.0

    @property
    def deadline(self) -> float | None:
        """When the limit passes (a ``time.perf_counter()`` value), ``None`` without one."""
        return None if self.time_limit is None else self.start + self.time_limit


@dataclass
class Record:
    """The attempts made so far for one plan, and the budget they run under."""

    budget: Budget
    entries: list[Attempt] = field(default_factory=list)

    def attempt(self, name: str, leg: int | None, run: Callable[[], T],
                catch: tuple[type[Exception], ...] = (SolverError,),
                until: float | None = None) -> T:
        """``run()`` as the attempt ``name``, recorded; an exception in ``catch`` is re-raised.

        Raises [`PlanTimeout`][speedplan.PlanTimeout] instead of starting ``run`` when the budget
        has run out. ``until`` (a ``time.perf_counter()`` value): an earlier deadline of this
        attempt's own, for the backends that can stop at one.
        """
        if self.budget.expired():
            self.entries.append(Attempt(name, leg, "skipped", "time limit reached", 0.0))
            raise self.timeout()
        at = min((t for t in (self.budget.deadline, until) if t is not None), default=None)
        t0 = time.perf_counter()
        try:
            with deadline(at):  # for backends that can stop at it
                result = run()
        except catch as exc:
            self.entries.append(Attempt(name, leg, "failed", _reason(exc),
                                        time.perf_counter() - t0))
            raise
        self.entries.append(Attempt(name, leg, "answered", "", time.perf_counter() - t0))
        return result

    def answer_seconds(self, leg: int | None) -> float:
        """How long the latest attempt that answered ``leg`` took [s] (0 if none did)."""
        return next((e.seconds for e in reversed(self.entries)
                     if e.leg == leg and e.outcome in ("answered", "replaced")), 0.0)

    def skip(self, name: str, leg: int | None, reason: str) -> None:
        """Record the attempt ``name`` as not started, saying why."""
        self.entries.append(Attempt(name, leg, "skipped", reason, 0.0))

    def mark_previous(self, leg: int | None, reason: str) -> None:
        """Mark the answer of ``leg`` before its latest one as replaced, saying why."""
        answered = [k for k, e in enumerate(self.entries)
                    if e.leg == leg and e.outcome == "answered"]
        if len(answered) >= 2:
            self.mark(answered[-2], "replaced", reason)

    def mark(self, k: int, outcome: AttemptOutcome, reason: str) -> None:
        """Set the outcome of entry ``k`` (an attempt whose result was discarded)."""
        self.entries[k] = replace(self.entries[k], outcome=outcome, reason=reason)

    def timeout(self) -> PlanTimeout:
        """The error for a budget that ran out before a verified plan."""
        limit = float(self.budget.time_limit or 0.0)
        return PlanTimeout(
            f"no verified plan within time_limit={limit:.6g} s ({self.budget.elapsed():.3g} s "
            f"spent); tried: {describe_attempts(self.entries)}. Pass a larger time_limit, or "
            "time_limit=None to run every attempt", time_limit=limit,
            attempts=tuple(self.entries))



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
    >>> path = Path.from_waypoints([[0, 0], [30, 0], [30, 10]])
    >>> model = build_model(PlanRequest.create(path, Limits(2, 1, 1, 0.5)))
    >>> leg = model.legs[0]
    >>> from speedplan.strategy import coarser_leg
    >>> half = coarser_leg(model.request, leg, 0.5)
    >>> bool(half.problem.n <= leg.problem.n // 2 + 1), bool(half.problem.s[-1] == leg.length)
    (True, True)
    """
    if not coarsenable(request, leg):
        return None
    nodes = max(int(leg.problem.n * factor), MIN_NODES)
    if nodes >= leg.problem.n:
        return None
    lo, hi = leg.start, leg.start + leg.length
    s = default_grid(request, leg.bound, lo, hi, leg.v0, leg.a0, leg.vf, leg.af, nodes)
    if s.size >= leg.problem.n:
        return None
    return leg_on_grid(request, leg.bound, s, lo, leg.v0, leg.a0, leg.vf, leg.af)


def coarsenable(request: PlanRequest, leg: Leg) -> bool:
    """Whether ``leg`` is on a jerk-limited default grid above `MIN_NODES` nodes.

    The legs `coarser_leg` can rebuild coarser (without building the grid).
    """
    return (request.n is None and request.ds is None and request.jerk_limited
            and leg.problem.n > MIN_NODES)


def _reason(exc: Exception) -> str:
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text[:300]}"


# ---- model ----------------------------------------------------------------------------------
def model_request(request: PlanRequest, record: Record) -> tuple[PlanRequest, Model]:
    """The request's model, else with exact reach envelopes, else with a hair more jerk.

    Moving boundary states are capped by the max-jerk motion (``reach="max_jerk"``), which
    keeps the relaxation exact but misses feasible motions whose speed first dips: if it
    refuses the states, the exact envelope in distance (``reach="distance"``) decides.

    Marginal states: a moving boundary state that ``j_max (1 + STATE_JERK_ROUNDING)``
    reaches (a state read off a plan, on the boundary of the reachable set up to the law's
    rounding) is planned with that jerk, silently, and so is one that ``j_max (1 +
    STATE_JERK_LAW_ROUNDING)`` reaches (read off the final jerk phase of a plan's stop); the
    looser jerk holds in the legs up to the state's first rest, ``j_max`` after it
    (`PlanRequest.leg_jerk`). One just outside what ``j_max`` reaches is planned with up to
    ``j_max (1 + STATE_JERK_SLACK)``, with a warning (a state measured on the vehicle:
    refusing it would strand the vehicle). The looser jerk is used only where the state
    needs it: its acceleration brought to 0 at constant jerk (`TurnLeg`,
    `PlanRequest.turn_jerk`), the rest of the move planned from there with ``j_max``.
    Where that turn does not fit (longer than the stretch, or above the speed bound) the
    jerk rows of the legs up to the state's first rest take the looser jerk
    (`PlanRequest.state_jerk`): held only
    near the state in the rows, the varying jerk bound made the relaxation inexact and a
    27.8 km move took minutes in the refinement instead of 1 s. The plan is verified
    against the requested limits.
    """
    moving = any(x != 0.0 for x in (request.v0, request.a0, request.vf, request.af))
    try:
        return request, record.attempt("model", None, lambda: build_model(request),
                                       catch=(InfeasibleError,))
    except InfeasibleError as exc:
        if not (moving and request.jerk_limited and exc.constraint in STATE_CONSTRAINTS):
            raise
        refusal = exc
    exact = replace(request, reach="distance")
    with contextlib.suppress(InfeasibleError):
        return exact, record.attempt("exact_reach", None, partial(build_model, exact),
                                     catch=(InfeasibleError,))
    j_max = request.limits.j_max
    rounding, slack = j_max * (1.0 + STATE_JERK_ROUNDING), state_jerk(j_max)
    law_rounding = j_max * (1.0 + STATE_JERK_LAW_ROUNDING)
    for name, looser in (
            ("state_rounding", replace(request, state_jerk=rounding)),
            ("exact_reach_state_rounding", replace(exact, state_jerk=rounding)),
            ("law_rounding", replace(request, state_jerk=law_rounding)),
            ("exact_reach_law_rounding", replace(exact, state_jerk=law_rounding)),
            ("jerk_slack", replace(request, turn_jerk=slack)),
            ("exact_reach_jerk_slack", replace(exact, turn_jerk=slack)),
            ("jerk_slack_whole_move", replace(request, state_jerk=slack)),
            ("exact_reach_jerk_slack_whole_move", replace(exact, state_jerk=slack))):
        with contextlib.suppress(InfeasibleError):
            model = record.attempt(name, None, partial(build_model, looser),
                                   catch=(InfeasibleError,))
            break
    else:
        raise refusal from None
    if "jerk_slack" in name:
        turns = [leg for leg in model.legs if isinstance(leg, TurnLeg)]
        where = ("only while the state's acceleration is brought to 0 (" + ", ".join(
            f"s={leg.start:.6g}..{leg.start + leg.length:.6g} m, {leg.motion.duration:.3g} s"
            for leg in turns) + "), j_max elsewhere") if turns else "over the whole move"
        used = max((abs(float(leg.motion.jerk[0])) for leg in turns), default=slack)
        warnings.warn(
            f"the boundary states are reachable only with up to {STATE_JERK_SLACK:.0%} more "
            f"jerk than j_max={j_max:.6g} m/s³ ({refusal}); planned with {used:.6g} m/s³ "
            f"{where}, within the jerk tolerance", SpeedplanWarning, stacklevel=4,
        )
    return looser, model


# ---- solve ----------------------------------------------------------------------------------
def solve_leg(leg: ModelLeg, *, fallback: bool = True, ipopt: bool = True) -> LegResult:
    """Solve one leg and build its law; an infeasibility is restated in metres.

    ``fallback``: whether a failed relaxation backend is retried with the other one;
    ``ipopt``: whether the refinement may fall back to IPOPT (`solve_problem`). A `ForcedLeg`,
    `TurnLeg` or `StraightLeg` carries its motion: only its law is built.
    """
    if isinstance(leg, ForcedLeg):
        return _known_motion(leg.start, law_for(leg.s, leg.w, leg.time_law), "forced")
    if isinstance(leg, TurnLeg):
        return _known_motion(leg.start, MotionLaw(leg.motion), "forced")
    if isinstance(leg, StraightLeg):
        return _known_motion(leg.start, MotionLaw(leg.motion), "closed_form")
    try:
        solution = solve_problem(leg.problem, refine=leg.refine, backend=leg.backend,
                                 fallback=fallback, ipopt_fallback=ipopt)
    except InfeasibleError as exc:
        raise explain_infeasible(exc, leg) from exc
    law = law_for(leg.problem.s, solution.w, leg.time_law)
    if not np.isfinite(law.duration):  # never hand out a trajectory that does not arrive
        raise SolverError(
            f"the speed law between s={leg.start:.6g} m and s={leg.start + leg.length:.6g} m "
            "comes to rest before its end: the grid does not resolve a boundary transient")
    return LegResult(start=leg.start, s=leg.problem.s, solution=solution, law=law)


def _known_motion(start: float, law: SpeedLaw, backend: str) -> LegResult:
    """The result of a leg whose motion is known exactly: its optimum, certified as such."""
    duration = law.duration
    solution = DiscreteSolution(
        w=law.w, objective=duration, lower_bound=duration, gap=0.0, exact=True,
        exact_a_priori=True, jerk_violation=0.0, refined=False, status="optimal",
        solve_time=0.0, backend=backend,
    )
    return LegResult(start=start, s=law.s, solution=solution, law=law)


def solve_legs(request: PlanRequest, model: Model, record: Record
               ) -> tuple[list[LegResult], list[bool]]:
    """Every leg's first answer, and whether it came from a coarser grid (see the module)."""
    results, coarsened = [], []
    for i, leg in enumerate(model.legs):
        result, coarse = _first_answer(request, leg, i, record)
        results.append(result)
        coarsened.append(coarse)
    return results, coarsened


def _first_answer(request: PlanRequest, leg: ModelLeg, i: int,
                  record: Record) -> tuple[LegResult, bool]:
    """The first of the leg's solve attempts that answers.

    Measured on slow-zone paths (``benchmarks/fuzz_zones.py``): both interior-point methods
    can stall on a fine default grid and converge on one with a half to an eighth of its
    nodes, in well under a second, where the other backend takes 10 s to 7 min on the fine
    grid to fail or to return a relaxation that needs IPOPT. So the backend alone is tried
    on the default grid and on the coarser ones, and only then the same grids with the other
    backend as well. A user grid is never changed.
    """
    if isinstance(leg, ForcedLeg | TurnLeg):
        return record.attempt("forced_motion", i, lambda: solve_leg(leg)), False
    if isinstance(leg, StraightLeg):
        return record.attempt("closed_form", i, lambda: solve_leg(leg)), False
    if not coarsenable(request, leg):
        return record.attempt("given_grid" if request.n is not None or request.ds is not None
                              else "default_grid", i, lambda: solve_leg(leg)), False
    grids: list[Leg] = [leg]  # each built inside its attempt: most default grids solve at once
    # A moving state on the edge of its reach leaves the refinement little or no interior:
    # the banded starts fail, and IPOPT then ran its 5 s to fail as well (twice on a road's
    # replan, 12.5 s, where the grid with rounded state rows or the coarser one answers in
    # 0.1 s; a replan 1.5 a_max / j_max before a stop spent 10 s in IPOPT on the coarser grid
    # and with the other backend, to fail). Such a leg's attempts run no IPOPT, but where
    # only IPOPT refines (friction-ellipse rows): over the 2 000 plans of bench_latency and
    # 4 037 replans next to stops, IPOPT answered none of them.
    pinned = _moving_state_at_j_max(request, leg)
    ipopt = not pinned or leg.problem.has_grip
    try:
        return record.attempt("default_grid", i, partial(solve_leg, leg, fallback=False,
                                                         ipopt=ipopt)), False
    except SolverError as exc:
        failures = [exc]
    # Only where the relaxation answered and the refinement found no feasible point: a stalled
    # backend would stall again on the same grid, where the coarser grids answer.
    if failures[0].backend == "ipopt" and pinned:
        with contextlib.suppress(SolverError, InfeasibleError):
            return record.attempt("state_rounding_on_grid", i,
                                  partial(_solve_state_rounded, request, leg),
                                  catch=(SolverError, InfeasibleError)), False
    for factor in COARSER_GRIDS:
        try:
            result = record.attempt(f"coarser_grid_1/{round(1 / factor)}", i,
                                    partial(_solve_coarser, request, grids, factor, ipopt))
        except SolverError as exc:
            failures.append(exc)
            continue
        except _NotCoarser:  # not recorded: nothing was tried
            break
        return result, True
    # Each grid with the backend that did not fail on it (the failed one is not run again).
    for grid, failed in zip(grids, failures, strict=True):
        run = (partial(solve_leg, replace(grid, backend=_other_backend(failed.backend)),
                       fallback=False, ipopt=ipopt) if failed.backend in ("banded", "clarabel")
               else partial(solve_leg, grid, ipopt=ipopt))  # both backends
        try:
            return record.attempt("other_backend", i, run), False
        except SolverError as exc:
            if grid is leg:
                failure = SolverError(
                    f"both relaxation backends failed on the default grid ({failed.backend}: "
                    f"{failed}; {exc.backend}: {exc}), and on its coarser grids",
                    backend=f"{failed.backend},{exc.backend}", status=exc.status)
    raise failure


def _moving_state_at_j_max(request: PlanRequest, leg: Leg) -> bool:
    """Whether ``leg`` starts or ends at a moving state of a request planned with ``j_max``.

    Such a state may sit on the edge of what ``j_max`` reaches further on
    (`speedplan.model.boundary.STATE_JERK_PINNED`).
    """
    moving = leg.v0 > 0.0 or leg.a0 != 0.0 or leg.vf > 0.0 or leg.af != 0.0
    return moving and request.state_jerk is None and request.turn_jerk is None


def _solve_state_rounded(request: PlanRequest, leg: Leg) -> LegResult:
    """``leg`` on its own grid with ``j_max (1 + STATE_JERK_PINNED)`` in its rows, solved."""
    looser = replace(request, state_jerk=request.limits.j_max * (1.0 + STATE_JERK_PINNED))
    rounded = leg_on_grid(looser, leg.bound, leg.problem.s, leg.start, leg.v0, leg.a0, leg.vf,
                          leg.af)
    return solve_leg(rounded, fallback=False, ipopt=False)


def _other_backend(failed: str) -> RelaxationBackend:
    """The relaxation backend that is not ``failed`` (``"banded"`` or ``"clarabel"``)."""
    return "clarabel" if failed == "banded" else "banded"


class _NotCoarser(Exception):
    """The default grid cannot get coarser (`coarser_leg`)."""


def _solve_coarser(request: PlanRequest, grids: list[Leg], factor: float,
                   ipopt: bool = True) -> LegResult:
    """The first leg of ``grids`` on a grid with ``factor`` times its nodes, solved.

    The grid is appended to ``grids``; `_NotCoarser` when it would not be coarser
    than the last one there. ``ipopt``: whether the refinement may fall back to IPOPT.
    """
    coarser = coarser_leg(request, grids[0], factor)
    if coarser is None or coarser.problem.n >= grids[-1].problem.n:
        raise _NotCoarser
    grids.append(coarser)
    return solve_leg(coarser, fallback=False, ipopt=ipopt)


# ---- verify ---------------------------------------------------------------------------------
def verified_profile(request: PlanRequest, model: Model, legs: list[LegResult],
                     coarsened: list[bool], record: Record) -> SpeedProfile:
    """The profile of ``legs``, refined locally where its law exceeds a tolerance, checked.

    Each leg is checked once per law it gets: the final verification merges these checks
    (what ``profile.verify()`` computes) instead of checking every leg again. With a budget
    that runs out while a leg still exceeds a limit, [`PlanTimeout`][speedplan.PlanTimeout].
    """
    profile = SpeedProfile(path=request.path, limits=request.limits, legs=tuple(legs),
                           speed_bound=model.bound, request=request)
    leg_checks = [profile.check_leg(i, leg.samples if isinstance(leg, Leg) else None)
                  for i, leg in enumerate(model.legs)]
    window = _Window.of(record)
    stuck: set[int] = set()  # legs whose refined law did not arrive: retrying repeats it
    for _ in range(MAX_REFINEMENTS):
        if all(c.verification.ok for c in leg_checks):
            break
        changed = []
        for i, (leg, leg_check) in enumerate(zip(model.legs, leg_checks, strict=True)):
            if leg_check.verification.ok or not isinstance(leg, Leg) or i in stuck:
                continue
            if not window.admits("local_refinement", i):
                stuck.add(i)
                continue
            grid = refined_grid(legs[i].s, leg_check.knots, leg_check.excess, leg.anchors,
                                refine_factor(leg_check.verification))
            try:
                # A refined grid finer than the relaxation resolves (a user grid at the
                # finest step the jerk bounds allow) is refused like a failed solve.
                refined = record.attempt("local_refinement", i,
                                         partial(_solve_on_grid, request, leg, grid),
                                         catch=(SolverError, InvalidInputError),
                                         until=window.until(i))
            except (SolverError, InvalidInputError):
                stuck.add(i)  # keep the verified law; its excess is reported below
                continue
            trial = replace(profile, legs=(*legs[:i], refined, *legs[i + 1:]))
            trial_check = trial.check_leg(i)
            if excess(trial_check.verification) > EXCESS_GROWTH * excess(leg_check.verification):
                # A finer grid the backend solved far less well (seen: 1.1x the jerk limit
                # became 25x): keep the better law, and stop refining this leg. A moderate
                # growth is kept: a later refinement often passes (seen: 1.17x, 1.19x, 1.28x, ok).
                record.mark(len(record.entries) - 1, "replaced",
                            f"{_exceeds(trial_check.verification)}, more than the law it "
                            "refined")
                stuck.add(i)
                continue
            record.mark_previous(i, _exceeds(leg_check.verification))
            legs[i], leg_checks[i] = refined, trial_check
            changed.append(i)
        profile = replace(profile, legs=tuple(legs))
        if not changed:
            break
    # A leg planned on a coarser grid (its backend had stalled on the default one) whose law
    # still exceeds a limit: the default grid with the other backend as well, if that law
    # passes (seen on a zone path whose eighth grid left six steps for the last rest phase).
    for i, (leg, coarse) in enumerate(zip(model.legs, coarsened, strict=True)):
        if coarse and not leg_checks[i].verification.ok and isinstance(leg, Leg):
            if not window.admits("default_grid_other_backend", i):
                continue
            with contextlib.suppress(SolverError):
                again = record.attempt("default_grid_other_backend", i,
                                       partial(solve_leg, leg), until=window.until(i))
                trial = replace(profile, legs=(*legs[:i], again, *legs[i + 1:]))
                trial_check = trial.check_leg(i)
                if trial_check.verification.ok:
                    record.mark_previous(i, _exceeds(leg_checks[i].verification))
                    profile, legs, leg_checks[i] = trial, list(trial.legs), trial_check
                else:
                    record.mark(len(record.entries) - 1, "replaced",
                                _exceeds(trial_check.verification))
    check = Verification.merged([c.verification for c in leg_checks])
    if not check.ok:
        if record.budget.expired():
            raise record.timeout()
        _warn_exceeded(check, record, request.n is not None or request.ds is not None)
    # The bound's memo (every position evaluated while planning) stays with the plan, not
    # with the profile a caller keeps (a bound without one is kept as it is).
    bound = model.bound if model.bound.memo is None else replace(model.bound, memo=None)
    return replace(profile, verification=check, limits_exceeded=not check.ok,
                   speed_bound=bound, attempts=tuple(record.entries))


def _warn_exceeded(check: Verification, record: Record, given_grid: bool) -> None:
    worst = ", ".join(f"{k} {r:.3f}× at s={check.where.get(k, float('nan')):.4g} m"
                      for k, r in check.violations.items())
    tried = [e for e in record.entries
             if e.name == "local_refinement" and e.outcome != "skipped"]
    rounds = sum(e.outcome != "failed" for e in tried)
    failed = (f" ({len(tried) - rounds}{' more' if rounds else ''} failed)"
              if len(tried) > rounds else "")
    if not any(e.reason.startswith(InvalidInputError.__name__) for e in tried):
        advice = "or plan with a finer grid (n or ds)"
    elif given_grid:  # its refinement would be finer than the relaxation resolves
        advice = "or plan on the default grid (without n or ds)"
    else:
        advice = "a finer grid is beyond what the relaxation resolves for these jerk bounds"
    warnings.warn(
        f"the planned trajectory exceeds limits beyond tolerance ({worst} of the limit) "
        f"after {rounds} local refinement{'s' * (rounds != 1)} of the grid{failed}; status "
        f"'limits_exceeded' — see profile.verification and profile.attempts, {advice}",
        LimitWarning, stacklevel=5,
    )


@dataclass
class _Window:
    """The time each leg's improving attempts may take.

    Without a caller's limit, `refinement_seconds` of the leg's first answer, counted over
    the attempts on that leg since the window opened; with one, what the limit leaves.
    """

    record: Record
    opened: int  # the record's entries before the window
    allowed: dict[int, float] = field(default_factory=dict)

    @classmethod
    def of(cls, record: Record) -> _Window:
        return cls(record, len(record.entries))

    def left(self, leg: int) -> float:
        """Seconds the leg's improvements have left."""
        if self.record.budget.deadline is not None:
            return self.record.budget.remaining()
        if leg not in self.allowed:
            self.allowed[leg] = refinement_seconds(self.record.answer_seconds(leg))
        spent = sum(e.seconds for e in self.record.entries[self.opened:] if e.leg == leg)
        return self.allowed[leg] - spent

    def until(self, leg: int) -> float:
        """When the leg's improvements must stop (a ``time.perf_counter()`` value)."""
        return time.perf_counter() + self.left(leg)

    def admits(self, name: str, leg: int) -> bool:
        """Whether the attempt ``name`` on ``leg`` would end in time; if not, it is skipped.

        It is judged to take as long as the leg's last solve.
        """
        if self.record.answer_seconds(leg) <= self.left(leg):
            return True
        allowed = self.allowed.get(leg)
        whose = ("the time limit" if allowed is None
                 else f"the {allowed:.3g} s for improving this leg's first answer")
        self.record.skip(name, leg, f"{whose} would be spent before it ended")
        return False


def refinement_seconds(first_answer: float) -> float:
    """The time the attempts improving a leg's first answer may take [s].

    As long as that answer took (``first_answer`` seconds), at least
    `MIN_REFINEMENT_SECONDS`: a plan takes about twice its first answers, not the minutes a
    relaxation backend can spend on a refined grid it does not suit (Clarabel, as the
    fallback of a 22 000-node comfort grid the banded kernel could not start on: 67 s).

    Examples
    --------
    >>> refinement_seconds(0.05), refinement_seconds(2.5)
    (1.0, 2.5)
    """
    return max(MIN_REFINEMENT_SECONDS, first_answer)


def _solve_on_grid(request: PlanRequest, leg: Leg, grid: FloatArray) -> LegResult:
    """``leg`` on another grid (a local refinement of its own), solved."""
    return solve_leg(leg_on_grid(request, leg.bound, grid, leg.start, leg.v0, leg.a0, leg.vf,
                                 leg.af))


def excess(check: Verification) -> float:
    """How far the worst limit is exceeded, in its own tolerances (``<= 1``: within them).

    Examples
    --------
    >>> from speedplan.timing import Verification
    >>> round(excess(Verification(maxima={}, ratios={"jerk": 1.1, "speed": 1.0}, where={})), 6)
    2.0
    """
    return max(((ratio - 1.0) / TOLERANCES[name] for name, ratio in check.ratios.items()),
               default=0.0)


def _exceeds(check: Verification) -> str:
    worst = ", ".join(f"{k} {r:.4g}×" for k, r in check.violations.items())
    return f"its law exceeds {worst} of the limit"


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

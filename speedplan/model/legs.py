"""What a model is made of: legs between standstills, their time-law options, the rests.

Pure data: `speedplan.model.build` fills them from a request, `speedplan.strategy` solves each
`Leg`'s problem (a `ForcedLeg`, `StraightLeg` or `TurnLeg` carries its motion already), and
`explain_infeasible` restates a discrete infeasibility of a leg's problem in speeds and metres
along the path.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.checks import FloatArray
from ..core.errors import InfeasibleError
from ..core.limits import Limits
from ..core.options import Backend, Refine, RestReason
from ..geometry import CellSamples, SpeedBound
from ..solve.problem import DiscreteProblem
from .request import PlanRequest
from .straight import JerkPhases

__all__ = ["ForcedLeg", "Leg", "Model", "ModelLeg", "Rest", "StraightLeg", "TimeLawSpec",
           "TurnLeg", "explain_infeasible"]

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
    reason : RestReason
        Why: ``"cusp"`` (the direction of travel flips), ``"stop"`` (asked for, e.g. a route
        node with a blocking action) or ``"curvature jump"`` (a G1 join with ``j_lat_max``
        set: the lateral acceleration would step).
    """

    s: float
    reason: RestReason


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
    refine : Refine
        Refinement mode; ``backend``: relaxation backend (from the request).
    anchors : ndarray
        Positions on the leg [m] its grids keep as nodes (joins of path pieces where the
        curvature rate jumps, with a lateral-jerk limit); empty when none.
    samples : CellSamples or None
        For a law linear in ``w`` (``time_law.linear``): the bound and the curvature at the
        `cell_points` of the grid, which gave the node bounds and which the law's check
        reads again; ``None`` otherwise.
    """

    bound: SpeedBound
    problem: DiscreteProblem
    time_law: TimeLawSpec
    limits: Limits
    refine: Refine = "auto"
    backend: Backend = "auto"
    anchors: FloatArray = field(default_factory=lambda: np.zeros(0))
    samples: CellSamples | None = None


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
class StraightLeg(_Ends):
    """A straight leg planned in closed form: its minimum-time motion is known exactly.

    A straight stretch with a constant speed bound whose boundary states a motion with one
    speed peak joins (`speedplan.model.straight`); ``start``, ``length`` and the boundary
    states are those of `Leg`.

    Attributes
    ----------
    motion : JerkPhases
        The minimum-time motion (positions from the leg's start).
    """

    motion: JerkPhases


@dataclass(frozen=True)
class TurnLeg(_Ends):
    """The turn of a marginal boundary state: its acceleration brought to 0 at constant jerk.

    A moving state just outside what ``j_max`` reaches (`speedplan.strategy.model_request`,
    attempt ``"jerk_slack"``) is planned with a little more jerk only here: from ``(v0, a0)``
    to ``(vf, 0)`` at the start of the request (from ``(v0, 0)`` to ``(vf, af)`` at its end),
    the rest of the move with ``j_max``. ``start``, ``length`` and the boundary states are
    those of `Leg`.

    Attributes
    ----------
    motion : JerkPhases
        The turn, one constant-jerk phase (positions from the leg's start).
    """

    motion: JerkPhases


#: Any leg of a `Model`.
ModelLeg = Leg | ForcedLeg | StraightLeg | TurnLeg


@dataclass(frozen=True)
class Model:
    """A request modelled as legs between standstills.

    Attributes
    ----------
    request : PlanRequest
        What was asked.
    bound : SpeedBound
        ``s -> mu+(s)`` [m²/s²] along the whole path.
    legs : tuple of Leg, ForcedLeg or StraightLeg
        In order; consecutive legs meet at rest.
    rests : tuple of Rest
        The points inside the path where the vehicle stops, in order.
    """

    request: PlanRequest
    bound: SpeedBound
    legs: tuple[ModelLeg, ...] = field(default_factory=tuple)
    rests: tuple[Rest, ...] = ()


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

"""SpeedProfile: the planned speed law along a path, its certificate, time law and checks."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cached_property
from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import ArrayLike

from .._version import __version__
from ..core import kinematics
from ..core.attempts import Attempt
from ..core.checks import FloatArray, as_array, as_scalar
from ..core.errors import InvalidInputError
from ..core.forward import Forwarded
from ..core.limits import Limits
from ..solve.solution import STATUSES as SOLUTION_STATUSES
from ..solve.solution import DiscreteSolution
from .law import LawChain, SpeedLaw, TimeLaw
from .trajectory import Trajectory
from .verify import LegCheck, Verification, bound_breakpoints, check_law, curvature_rate

if TYPE_CHECKING:
    from ..geometry import CellSamples, Path
    from ..model import PlanRequest
    from ..model.legs import TimeLawSpec

__all__ = ["PROFILE_STATUSES", "LegResult", "ProfileStatus", "SpeedProfile", "combine",
           "sample_times"]

#: More samples than this is a mistake in ``dt`` (and gigabytes of memory), not a request.
MAX_SAMPLES = 50_000_000

#: ``SpeedProfile.status``: the solution statuses, and one that says the limits are exceeded.
ProfileStatus = Literal["optimal", "refined", "scaled", "relaxed", "limits_exceeded"]

#: What each `ProfileStatus` means.
PROFILE_STATUSES: dict[str, str] = {
    **SOLUTION_STATUSES,
    "limits_exceeded": "the continuous trajectory exceeds a limit beyond its tolerance even "
    "after local refinement of the grid (see verification); never returned as 'optimal'",
}

_WORST = ("optimal", "refined", "scaled", "relaxed")


@dataclass(frozen=True, eq=False)
class LegResult:
    """One leg of a profile: where it lies, its discrete solution and its law.

    Attributes
    ----------
    start : float
        Arc length of the leg's start along the path [m].
    s : ndarray
        The leg's grid, from 0 [m].
    solution : DiscreteSolution
        Its discrete solve (a forced leg has ``backend == "forced"``).
    law : SpeedLaw
        Its continuous law (a `TimeLaw`, or a `MotionLaw` for a motion known in closed form).
    check : LegCheck or None
        Its verification.
    """

    start: float
    s: FloatArray
    solution: DiscreteSolution
    law: SpeedLaw
    check: LegCheck | None = None


def combine(solutions: list[DiscreteSolution]) -> DiscreteSolution:
    """One certificate for legs solved separately: sums of objectives and bounds.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.timing.profile import combine
    >>> from speedplan.solve.solution import DiscreteSolution
    >>> one = DiscreteSolution(w=np.zeros(3), objective=2.0, lower_bound=2.0, gap=0.0,
    ...                        exact=True, exact_a_priori=True, jerk_violation=0.0,
    ...                        refined=False, status="optimal", solve_time=0.1, backend="pass")
    >>> both = combine([one, one])
    >>> both.objective, both.w.size, both.status
    (4.0, 5, 'optimal')
    """
    if len(solutions) == 1:
        return solutions[0]
    objective = float(sum(x.objective for x in solutions))
    lower = float(sum(x.lower_bound for x in solutions))
    w = np.concatenate([solutions[0].w] + [x.w[1:] for x in solutions[1:]])
    status = max((x.status for x in solutions), key=_WORST.index)
    backends = sorted({x.backend for x in solutions})
    return DiscreteSolution(
        w=w, objective=objective, lower_bound=lower,
        gap=(objective - lower) / lower if lower > 0 else 0.0,
        exact=all(x.exact for x in solutions),
        exact_a_priori=all(x.exact_a_priori for x in solutions),
        jerk_violation=max(x.jerk_violation for x in solutions),
        refined=any(x.refined for x in solutions), status=status,
        solve_time=float(sum(x.solve_time for x in solutions)), backend="+".join(backends),
    )


@dataclass(frozen=True, eq=False)
class SpeedProfile:
    """Minimum-time speed law along a path, with its certificate and time law.

    Built by `speedplan.plan`; not usually constructed by hand. A path with cusps, or a
    boundary state that forces a stop on the way, is planned as several *legs* that meet at
    rest (``legs``); every array here covers the whole path.

    Attributes
    ----------
    path : Path
        The path followed.
    limits : Limits
        The limits planned for.
    legs : tuple of LegResult
        The legs, in order.
    speed_bound : callable
        ``s -> mu+(s)``, the squared-speed bound from limits, curvature and zones [m²/s²].
    request : PlanRequest or None
        The validated arguments [`speedplan.plan`][speedplan.plan] was called with.
    verification : Verification or None
        The check [`speedplan.plan`][speedplan.plan] ran.
    limits_exceeded : bool
        Whether that check still failed after local refinement (then `status` is
        ``"limits_exceeded"``).
    attempts : tuple of Attempt
        The attempts of the planning strategy, in order (`speedplan.strategy`): for
        the request and for each leg, which one answered (``outcome == "answered"``) and
        why each other failed or was replaced
        ([`Attempt`][speedplan.core.attempts.Attempt]). Empty for a profile built by hand.
    objective : float
        Discrete objective ``Σ τ_i / sqrt(w_i)`` that the solver minimised [s].
    lower_bound : float
        Certified lower bound on the discrete objective's optimum [s].
    gap : float
        Relative optimality gap of the discrete problem (0 when exact).
    exact : bool
        Whether the convex relaxation was exact (global optimum certified).
    """

    path: Path
    limits: Limits
    legs: tuple[LegResult, ...]
    speed_bound: Callable[[FloatArray], FloatArray]
    request: PlanRequest | None = None
    verification: Verification | None = None
    limits_exceeded: bool = False
    attempts: tuple[Attempt, ...] = ()

    # ---- the speed law on the grid ----------------------------------------------------------
    @cached_property
    def law(self) -> LawChain:
        """The continuous law along the whole path."""
        return LawChain(tuple(leg.law for leg in self.legs),
                        np.array([leg.start for leg in self.legs]))

    @cached_property
    def s(self) -> FloatArray:
        """Arc-length grid of every leg, shared stop nodes once [m]."""
        parts = [leg.start + leg.s for leg in self.legs]
        return np.concatenate([parts[0]] + [p[1:] for p in parts[1:]])

    @cached_property
    def solution(self) -> DiscreteSolution:
        """The discrete solution (the legs' combined certificate when there are several)."""
        return combine([leg.solution for leg in self.legs])

    @property
    def w(self) -> FloatArray:
        """Squared speed at the grid nodes [m²/s²]."""
        return self.solution.w

    @property
    def v(self) -> FloatArray:
        """Speed at the grid nodes [m/s]."""
        out: FloatArray = np.sqrt(np.maximum(self.w, 0.0))
        return out

    @cached_property
    def t(self) -> FloatArray:
        """Time at which each grid node is reached [s]."""
        return self.law.node_times

    @property
    def duration(self) -> float:
        """Travel time of the continuous time law [s]."""
        return self.law.duration

    # ---- certificate (of the discrete problem), documented in the class docstring -----------
    objective = Forwarded[float]("solution", "objective")
    lower_bound = Forwarded[float]("solution", "lower_bound")
    gap = Forwarded[float]("solution", "gap")
    exact = Forwarded[bool]("solution", "exact")

    @property
    def status(self) -> ProfileStatus:
        """One of `PROFILE_STATUSES`: the solution's, or ``"limits_exceeded"``."""
        return "limits_exceeded" if self.limits_exceeded else self.solution.status

    @property
    def message(self) -> str:
        """What [`status`][speedplan.SpeedProfile.status] means."""
        return PROFILE_STATUSES[self.status]

    # ---- sampling in time -------------------------------------------------------------------
    def at(self, t: ArrayLike) -> Trajectory:
        """States at the given times [s] (clipped to ``[0, duration]``).

        Examples
        --------
        >>> from speedplan import Limits, Path, plan
        >>> prof = plan(Path.from_waypoints([[0, 0], [10, 0]], kind="polyline"),
        ...             Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
        >>> state = prof.at([0.0, prof.duration])
        >>> state.v.round(9).tolist(), state.s.round(9).tolist()
        ([0.0, 0.0], [0.0, 10.0])
        """
        times = as_array("t", t)
        if times.ndim > 1:
            raise InvalidInputError(f"`t` must be a number or a 1-D array of times [s]; got "
                                    f"shape {times.shape} (pass t.ravel() for every entry)")
        tt = np.clip(np.atleast_1d(times), 0.0, self.duration)
        q, w, v, a, jerk = self.law.state_at(tt)
        xy, heading, kappa = self.path.evaluate(q)
        xy = np.asarray(xy).reshape(-1, 2)
        direction = (np.asarray(self.path.direction(q), dtype=np.float64)
                     if hasattr(self.path, "direction") else np.ones(q.size))
        lat_jerk = kinematics.lateral_jerk(kappa, curvature_rate(self.path, q), w, a, v)
        return Trajectory(
            t=tt, s=q, x=xy[:, 0], y=xy[:, 1], heading=np.asarray(heading, dtype=np.float64),
            curvature=kappa, v=v, a=a, j=jerk, a_lat=kinematics.lateral_acceleration(kappa, w),
            yaw_rate=kinematics.yaw_rate(kappa, v), j_lat=lat_jerk, direction=direction,
        )

    def sample(self, dt: float = 0.01) -> Trajectory:
        """Trajectory sampled every ``dt`` seconds from 0; the last sample is at ``duration``.

        Its ``metadata`` records how it was made (`metadata`, and ``dt``), so an exported
        file can be interpreted later.

        Parameters
        ----------
        dt : float
            Sampling period [s], > 0.

        Examples
        --------
        >>> from speedplan import Limits, Path, plan
        >>> prof = plan(Path.from_waypoints([[0, 0], [10, 0]], kind="polyline"),
        ...             Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
        >>> traj = prof.sample(0.1)
        >>> traj.t[-1] == prof.duration, traj.metadata["status"], traj.metadata["dt"]
        (np.True_, 'optimal', 0.1)
        """
        times = sample_times(self.duration, dt)
        return replace(self.at(times), metadata={**self.metadata, "dt": float(dt)})

    @property
    def metadata(self) -> dict[str, object]:
        """What a trajectory file records about this plan: version, certificate, limits, inputs.

        Keys: ``speedplan_version``, ``status``, ``duration`` [s], ``objective`` and
        ``lower_bound`` [s], ``gap``, ``grid_nodes``, ``backend``, ``refined``, ``limits``,
        and, for a profile from `speedplan.plan`, ``boundary`` (``v0``, ``a0``, ``vf``,
        ``af``) and ``standstill``.
        """
        meta: dict[str, object] = {
            "speedplan_version": __version__,
            "status": self.status,
            "duration": self.duration,
            "objective": self.objective,
            "lower_bound": self.lower_bound,
            "gap": self.gap,
            "grid_nodes": int(self.s.size),
            "backend": self.solution.backend,
            "refined": self.solution.refined,
            "limits": self.limits,
        }
        if self.request is not None:
            req = self.request
            meta["boundary"] = {"v0": req.v0, "a0": req.a0, "vf": req.vf, "af": req.af}
            meta["standstill"] = req.standstill
        return meta

    # ---- checks ---------------------------------------------------------------------------
    def verify(self) -> Verification:
        """Compare the continuous trajectory with the limits (see `speedplan.timing.verify`).

        Acceleration and jerk: exact extremes of every piece of the law. Speed bound, lateral
        acceleration, yaw rate and lateral jerk: at 8 points per grid cell, at each piece's
        speed maximum and at the speed bound's breakpoints (zone and span ends, ``v_limit``
        knots, path joins).
        """
        return Verification.merged([self.check_leg(i).verification
                                    for i in range(len(self.legs))])

    def check_leg(self, i: int, samples: CellSamples | None = None) -> LegCheck:
        """The check of leg ``i`` (which of its law pieces exceed a tolerance).

        ``samples``: the speed bound at the `cell_points` of the leg's grid, as its model
        evaluated them (`speedplan.model.Leg`), which the check of a law linear in ``w``
        reads instead of evaluating the bound there again (see `check_law`).
        """
        leg = self.legs[i]
        return check_law(leg.law, leg.start, self.path, self.speed_bound, self.limits,
                         self._bound_breaks, samples)

    @cached_property
    def _bound_breaks(self) -> FloatArray:
        """Breakpoints of the speed bound (`bound_breakpoints`), once for every leg."""
        return bound_breakpoints(self.path, self.speed_bound)

    def __repr__(self) -> str:
        return (
            f"SpeedProfile(duration={self.duration:.6g} s, length={self.path.length:.6g} m, "
            f"status={self.status!r}, gap={self.gap:.3g}, n={self.s.size}, legs={len(self.legs)})"
        )


def law_for(s: FloatArray, w: FloatArray, spec: TimeLawSpec) -> TimeLaw:
    """The `TimeLaw` of a leg's solution under its `TimeLawSpec`."""
    return TimeLaw(s, w, accel_start=spec.accel_start, accel_end=spec.accel_end,
                   j_max=spec.j_max, linear=spec.linear)


def sample_times(duration: float, dt: float) -> FloatArray:
    """``0, dt, 2 dt, ...`` up to ``duration``, which is always the last sample [s].

    Examples
    --------
    >>> sample_times(1.0, 0.3).tolist()
    [0.0, 0.3, 0.6, 0.8999999999999999, 1.0]
    """
    step = as_scalar("dt", dt, positive=True)
    n = int(np.floor(duration / step + 1e-9)) + 1
    if n > MAX_SAMPLES:
        raise InvalidInputError(
            f"`dt`={step!r} gives {n} samples for a {duration:.6g} s trajectory; use a larger dt"
        )
    times: FloatArray = np.arange(n, dtype=np.float64) * step
    if times[-1] < duration - 1e-12 * max(1.0, duration):
        times = np.append(times, duration)
    return times

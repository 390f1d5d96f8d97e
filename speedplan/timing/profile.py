"""SpeedProfile: the planned speed law along a path, its time law and its checks."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np

from ..core.checks import FloatArray, as_array, as_scalar
from ..core.errors import InvalidInputError
from ..core.limits import Limits
from ..geometry.bounds import SpeedBound
from ..solve.solution import DiscreteSolution
from .law import TimeLaw
from .trajectory import Trajectory
from .verify import Verification

if TYPE_CHECKING:
    from ..geometry import Path
    from ..model import PlanRequest

__all__ = ["SpeedProfile"]


@dataclass(frozen=True, eq=False)
class SpeedProfile:
    """Minimum-time speed law along a path, with its certificate and time law.

    Built by :func:`speedplan.plan`; not usually constructed by hand.

    Attributes
    ----------
    path : Path
        The path followed.
    limits : Limits
        The limits planned for.
    s : ndarray
        Arc-length grid of the discrete problem [m].
    w : ndarray
        Squared speed at the grid nodes [m²/s²].
    solution : DiscreteSolution
        The discrete solve with its certificate (``lower_bound``, ``gap``, ``status``).
    law : TimeLaw
        The continuous time law built from ``w``.
    speed_bound : callable
        ``s -> mu+(s)``, the squared-speed bound from limits, curvature and zones [m²/s²].
    request : PlanRequest or None
        The validated arguments :func:`speedplan.plan` was called with.
    verification : Verification or None
        The check :func:`speedplan.plan` ran (``verify()`` at its default sampling).
    """

    path: Path
    limits: Limits
    s: FloatArray
    w: FloatArray
    solution: DiscreteSolution
    law: TimeLaw
    speed_bound: Callable[[FloatArray], FloatArray]
    request: PlanRequest | None = None
    verification: Verification | None = None

    # ---- the speed law on the grid ----------------------------------------------------------
    @property
    def v(self) -> FloatArray:
        """Speed at the grid nodes [m/s]."""
        out: FloatArray = np.sqrt(np.maximum(self.w, 0.0))
        return out

    @cached_property
    def t(self) -> FloatArray:
        """Time at which each grid node is reached [s]."""
        return self.law.time_at(self.s)

    @property
    def duration(self) -> float:
        """Travel time of the continuous time law [s]."""
        return self.law.duration

    # ---- certificate (of the discrete problem) ----------------------------------------------
    @property
    def objective(self) -> float:
        """Discrete objective ``Σ τ_i / sqrt(w_i)`` that the solver minimised [s]."""
        return self.solution.objective

    @property
    def lower_bound(self) -> float:
        """Certified lower bound on the discrete objective's optimum [s]."""
        return self.solution.lower_bound

    @property
    def gap(self) -> float:
        """Relative optimality gap of the discrete problem (0 when exact)."""
        return self.solution.gap

    @property
    def exact(self) -> bool:
        """Whether the convex relaxation was exact (global optimum certified)."""
        return self.solution.exact

    @property
    def status(self) -> str:
        """Solver status, see :data:`speedplan.solve.STATUSES`."""
        return self.solution.status

    # ---- sampling in time -------------------------------------------------------------------
    def at(self, t: Any) -> Trajectory:
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
        tt = np.clip(np.atleast_1d(times), 0.0, self.duration)
        q, v, a, jerk, kappa = self._motion(tt)
        xy = np.asarray(self.path.point(q)).reshape(-1, 2)
        return Trajectory(
            t=tt, s=q, x=xy[:, 0], y=xy[:, 1],
            heading=np.asarray(self.path.heading(q), dtype=np.float64),
            curvature=kappa, v=v, a=a, j=jerk, a_lat=kappa * v * v,
        )

    def _motion(
        self, tt: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
        """``s, v, a, j`` and the curvature at times ``tt`` (within ``[0, duration]``)."""
        q = self.law.position_at(tt)
        _, v, a, jerk = self.law.kinematics(q)
        return q, v, a, jerk, np.asarray(self.path.curvature(q), dtype=np.float64)

    def sample(self, dt: float = 0.01) -> Trajectory:
        """Trajectory sampled every ``dt`` seconds from 0; the last sample is at ``duration``.

        Parameters
        ----------
        dt : float
            Sampling period [s], > 0.
        """
        return self.at(self._sample_times(dt))

    def _sample_times(self, dt: float) -> FloatArray:
        """``0, dt, 2 dt, ...`` up to the duration, which is always the last sample."""
        step = as_scalar("dt", dt, positive=True)
        n = int(np.floor(self.duration / step + 1e-9)) + 1
        if n > 50_000_000:
            raise InvalidInputError(
                f"`dt`={step!r} gives {n} samples for a {self.duration:.6g} s trajectory; "
                "use a larger dt"
            )
        times: FloatArray = np.arange(n, dtype=np.float64) * step
        if times[-1] < self.duration - 1e-12 * max(1.0, self.duration):
            times = np.append(times, self.duration)
        return times

    # ---- checks ---------------------------------------------------------------------------
    def verify(self, dt: float | None = None) -> Verification:
        """Measure the realised maxima on a fine time sampling and compare with the limits.

        Parameters
        ----------
        dt : float, optional
            Sampling period [s]; default 1 ms, or ``duration / 200 000`` if that is longer.
        """
        step = dt if dt is not None else max(1e-3, self.duration / 200_000)
        # The states of sample(step) that the limits involve: positions and headings are not
        # needed, and on clothoid paths they cost as much as the time law.
        q, v, a, jerk, kappa = self._motion(self._sample_times(step))
        a_lat = kappa * v * v
        lim = self.limits
        bound_fn = self.speed_bound
        if isinstance(bound_fn, SpeedBound) and bound_fn.path is self.path:  # reuse curvature
            bound = bound_fn.given_curvature(q, kappa)
        else:
            bound = bound_fn(q)
        with np.errstate(divide="ignore", invalid="ignore"):
            speed_ratio = np.where(bound > 0, v / np.sqrt(bound), np.where(v > 0, np.inf, 0.0))

        def ratio(value: float, limit: float) -> float:
            if not np.isfinite(value):
                return float("inf")  # a NaN or infinite sample is a violation, never ignored
            return float(value / limit) if np.isfinite(limit) else 0.0

        max_accel = float(np.max(np.append(a, 0.0)))
        max_decel = float(np.max(np.append(-a, 0.0)))
        max_jerk = float(np.max(np.abs(jerk)))
        max_lat = float(np.max(np.abs(a_lat)))
        return Verification(
            max_speed=float(v.max()),
            max_accel=max_accel,
            max_decel=max_decel,
            max_jerk=max_jerk,
            max_lateral=max_lat,
            ratios={
                "speed": ratio(float(speed_ratio.max()), 1.0),
                "accel": ratio(max_accel, lim.a_max),
                "decel": ratio(max_decel, lim.a_decel),
                "lateral": ratio(max_lat, lim.a_lat_max),
                "jerk": ratio(max_jerk, lim.j_max),
            },
            dt=float(step),
        )

    def __repr__(self) -> str:
        return (
            f"SpeedProfile(duration={self.duration:.6g} s, length={self.path.length:.6g} m, "
            f"status={self.status!r}, gap={self.gap:.3g}, n={self.s.size})"
        )

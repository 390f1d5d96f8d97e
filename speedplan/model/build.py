"""From a physical request to the discrete problem: bounds, envelopes, grid, jerk rows.

:func:`build_model` is the one place where limits in SI units become the rows of a
:class:`~speedplan.solve.DiscreteProblem`; :meth:`Model.solve` solves it and restates a
discrete infeasibility in speeds and metres.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.checks import FloatArray
from ..core.errors import InfeasibleError, InvalidInputError
from ..geometry import SpeedBound
from ..solve import DiscreteProblem, DiscreteSolution, solve_problem
from .boundary import check_boundary_state, jerk_motion_w
from .grid import adaptive_grid, uniform_grid
from .request import PlanRequest
from .standstill import calibrate_standstill_rows

__all__ = ["NO_JERK_NODES", "Model", "TimeLawSpec", "build_model", "node_bounds"]

#: Uniform grid of a request without jerk limit (the O(n) pass is exact on any grid).
NO_JERK_NODES = 1001


@dataclass(frozen=True)
class TimeLawSpec:
    """How the time law interpolates the solved ``w`` (see :class:`speedplan.timing.TimeLaw`).

    Attributes
    ----------
    p : float
        Exponent of the interpolated ``u = w^p``: 3/4 for a smooth standstill, 1 otherwise.
    accel_start, accel_end : float or None
        Prescribed accelerations at moving ends [m/s²]; ``None`` keeps the discrete slope.
    """

    p: float
    accel_start: float | None
    accel_end: float | None


@dataclass(frozen=True)
class Model:
    """A request modelled as a discrete problem.

    Attributes
    ----------
    request : PlanRequest
        What was asked.
    bound : SpeedBound
        ``s -> mu+(s)`` [m²/s²] (limits, curvature, zones, ``v_limit``).
    problem : DiscreteProblem
        Grid, node bounds (with the boundary envelopes), acceleration and jerk rows.
    time_law : TimeLawSpec
        How to build the continuous time law from the solution.
    """

    request: PlanRequest
    bound: SpeedBound
    problem: DiscreteProblem
    time_law: TimeLawSpec

    def solve(self) -> DiscreteSolution:
        """Solve the discrete problem; an infeasibility is restated in speeds and metres."""
        try:
            return solve_problem(self.problem, refine=self.request.refine,
                                 backend=self.request.backend)
        except InfeasibleError as exc:
            raise explain_infeasible(exc, self) from exc


def build_model(request: PlanRequest) -> Model:
    """Model ``request`` as a discrete problem.

    Raises
    ------
    InvalidInputError
        A boundary speed above the speed bound, or a speed bound of 0 inside the path.
    InfeasibleError
        A boundary state no jerk-limited motion can leave or reach.
    """
    lim = request.limits
    check_boundary_state(request.v0, request.a0, lim.j_max, end=False)
    check_boundary_state(request.vf, request.af, lim.j_max, end=True)
    zone_list = None if request.zones is None else list(request.zones)
    bound = SpeedBound(request.path, lim, zone_list, request.v_limit)
    length = float(request.path.length)
    _check_end_speeds(request, bound, length)
    envelopes = _Envelopes(request, length)

    if request.n is not None or request.ds is not None:
        s = uniform_grid(length, n=request.n, ds=request.ds)
    elif request.jerk_limited:
        s = adaptive_grid(length, lambda q: envelopes.cap(q, bound(q)), a_max=lim.a_max,
                          a_decel=lim.a_decel, v_max=lim.v_max, j_max=lim.j_max,
                          w_start=request.v0**2, w_end=request.vf**2)
    else:
        s = uniform_grid(length, n=NO_JERK_NODES)
    w_max = envelopes.cap(s, node_bounds(bound, s))
    w_max[0] = max(w_max[0], request.v0**2)
    w_max[-1] = max(w_max[-1], request.vf**2)
    if (w_max[1:-1] <= 0).any():
        i = int(np.flatnonzero(w_max[1:-1] <= 0)[0]) + 1
        raise InvalidInputError(
            f"the speed bound is 0 at s={s[i]:.6g} m inside the path (infinite curvature, e.g. "
            "a sharp polyline corner, or a zone with v_max=0); round the corners "
            "(Path.from_waypoints(..., kind='clothoid')) or split the path there"
        )
    m = s.size
    jerk = np.full(m - 2, lim.J)
    if request.smooth_standstill:
        calibrate_standstill_rows(jerk, s, request.v0, request.a0, request.vf, request.af,
                                  lim.j_max)
    problem = DiscreteProblem(
        s=s, w_max=w_max,
        accel=np.full(m - 1, lim.A), decel=np.full(m - 1, lim.A_decel),
        jerk=jerk, w_start=request.v0**2, w_end=request.vf**2, w_min=envelopes.floor(s),
    )
    law = TimeLawSpec(
        p=0.75 if request.smooth_standstill else 1.0,
        accel_start=request.a0 if request.v0 > 0 else None,
        accel_end=request.af if request.vf > 0 else None,
    )
    return Model(request=request, bound=bound, problem=problem, time_law=law)


def _check_end_speeds(request: PlanRequest, bound: SpeedBound, length: float) -> None:
    ends = bound(np.array([0.0, length]))
    for name, v, b, where in (("v0", request.v0, ends[0], 0.0),
                              ("vf", request.vf, ends[1], length)):
        if v * v > b * (1 + 1e-9):
            raise InvalidInputError(
                f"`{name}`={v!r} m/s exceeds the speed bound {np.sqrt(b):.6g} m/s at "
                f"s={where:.6g} m (v_max, lateral acceleration or a zone); pass a lower speed"
            )


@dataclass(frozen=True)
class _Envelopes:
    """Jerk-limited envelopes of the motions leaving the start state and reaching the end."""

    request: PlanRequest
    length: float

    def cap(self, s: FloatArray, w: FloatArray) -> FloatArray:
        """``w`` capped by the fastest motion leaving (v0, a0) and arriving at (vf, af)."""
        req, lim = self.request, self.request.limits
        if req.smooth_standstill:
            w = np.minimum(w, jerk_motion_w(s, req.v0, req.a0, lim.j_max, lim.a_max))
            w = np.minimum(w, jerk_motion_w(self.length - s, req.vf, -req.af, lim.j_max,
                                            lim.a_decel))
        return w

    def floor(self, s: FloatArray) -> FloatArray | None:
        """The slowest motion leaving a moving start (and arriving at a moving end)."""
        req, lim = self.request, self.request.limits
        if not req.smooth_standstill or (req.v0 == 0.0 and req.vf == 0.0):
            return None
        lo = np.zeros_like(s)
        if req.v0 > 0:
            lo = np.maximum(lo, jerk_motion_w(s, req.v0, min(req.a0, 0.0), -lim.j_max,
                                              -lim.a_decel))
        if req.vf > 0:
            lo = np.maximum(lo, jerk_motion_w(self.length - s, req.vf, min(-req.af, 0.0),
                                              -lim.j_max, -lim.a_max))
        return lo


def node_bounds(bound: Any, s: FloatArray, per_interval: int = 8) -> FloatArray:
    """Bound at each node: the minimum of ``bound`` over its two adjacent intervals.

    The discrete problem sees the bound only at nodes; taking the minimum over the neighbouring
    intervals keeps the interpolated speed under a bound that drops between nodes (a zone
    entry, a curvature peak) at an ``O(h)`` cost where the bound is smooth.
    """
    frac = np.linspace(0.0, 1.0, per_interval + 1)
    sub = s[:-1, None] + np.diff(s)[:, None] * frac[None, :]
    interval_min = bound(sub.ravel()).reshape(sub.shape).min(axis=1)
    w = bound(s)
    w[:-1] = np.minimum(w[:-1], interval_min)
    w[1:] = np.minimum(w[1:], interval_min)
    return np.asarray(w, dtype=np.float64)


def explain_infeasible(exc: InfeasibleError, model: Model) -> InfeasibleError:
    """Restate a discrete infeasibility in speeds and metres."""
    where = exc.s
    problem, lim, req = model.problem, model.request.limits, model.request
    if where is None:
        return InfeasibleError(f"no speed law meets the request: {exc}", constraint=exc.constraint)
    i = int(np.argmin(np.abs(problem.s - where)))
    v_there = float(np.sqrt(problem.w_max[i]))
    if exc.constraint == "decel":
        msg = (f"cannot brake from v0={req.v0:.6g} m/s to {v_there:.6g} m/s (the speed bound at "
               f"s={where:.4g} m) under a_decel={lim.a_decel:.6g} m/s²")
    elif exc.constraint == "jerk":
        msg = (f"cannot brake from v0={req.v0:.6g} m/s to {v_there:.6g} m/s (the speed bound at "
               f"s={where:.4g} m) under j_max={lim.j_max:.6g} m/s³ and "
               f"a_decel={lim.a_decel:.6g} m/s²")
    elif exc.constraint == "accel":
        msg = (f"cannot reach vf={req.vf:.6g} m/s at the end from {v_there:.6g} m/s (the speed "
               f"bound at s={where:.4g} m) under a_max={lim.a_max:.6g} m/s²")
    else:
        msg = str(exc)
    return InfeasibleError(msg, constraint=exc.constraint, s=where)

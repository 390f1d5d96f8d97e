"""plan(): validate the request -> model it -> solve -> time law -> verified profile."""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

from .core.errors import LimitWarning
from .core.limits import Limits
from .geometry import Path, SpeedBound, SpeedZone
from .model import PlanRequest, build_model
from .model.request import STANDSTILL_MODES
from .timing import SpeedProfile, TimeLaw

# SpeedBound is re-exported so that pickles made when it lived here still load.
__all__ = ["STANDSTILL_MODES", "SpeedBound", "plan", "plan_request"]


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
) -> SpeedProfile:
    """Plan the minimum-time speed law along ``path`` under ``limits``.

    Parameters
    ----------
    path : Path
        Arc-length parametrised path.
    limits : Limits
        Speed, acceleration, braking, lateral acceleration and jerk limits (SI).
    n, ds : int or float, optional
        Uniform grid with ``n`` nodes or step at most ``ds`` [m]. By default the grid is
        adaptive: ~80 nodes per jerk transition, finer near standstill.
    v0, a0 : float
        Speed [m/s] and acceleration [m/s²] at the start (default: at rest).
    vf, af : float
        Speed and acceleration at the end (default: at rest).
    zones : sequence of SpeedZone, optional
        Polygons with their own speed limit.
    v_limit : tuple (s, v), optional
        Per-position speed limit along the path (see :func:`speedplan.speed_bounds`).
    refine : {"auto", "always", "never"}
        IPOPT refinement when the relaxation is not exact (see :func:`solve_discrete`).
    standstill : {"smooth", "free"}
        ``"smooth"`` (default): acceleration 0 at a standstill, jerk-limited from the first
        instant. ``"free"``: the paper's model, where acceleration may jump at a standstill.
    backend : {"auto", "clarabel", "banded"}
        Relaxation backend (see :func:`speedplan.solve_discrete`).

    Returns
    -------
    SpeedProfile
        The speed law, its certificate, and ``sample(dt)`` for a time trajectory. A
        :class:`~speedplan.LimitWarning` is issued when :meth:`SpeedProfile.verify` finds a
        limit exceeded beyond its tolerance.

    Raises
    ------
    InvalidInputError
        Malformed arguments, a path shorter than ``1e-9 v_max² / a_max`` (nearly coincident
        waypoints), or boundary states beyond the limits.
    InfeasibleError
        No speed law meets the boundary states (the message says which constraint, where).

    Examples
    --------
    A 30 m straight move from rest to rest; the jerk-limited optimum takes 19 s:

    >>> from speedplan import Limits, Path, plan
    >>> path = Path.from_waypoints([[0, 0], [30, 0]], kind="polyline")
    >>> prof = plan(path, Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
    >>> round(prof.duration, 1), prof.status
    (19.0, 'optimal')
    >>> traj = prof.sample(dt=0.01)
    >>> bool(traj.v.max() <= 2.0 * 1.005)
    True
    """
    request = PlanRequest.create(
        path, limits, n=n, ds=ds, v0=v0, a0=a0, vf=vf, af=af, zones=zones, v_limit=v_limit,
        refine=refine, standstill=standstill, backend=backend,
    )
    return plan_request(request)


def plan_request(request: PlanRequest) -> SpeedProfile:
    """:func:`plan` for an already validated :class:`~speedplan.model.PlanRequest`."""
    model = build_model(request)
    solution = model.solve()
    spec = model.time_law
    law = TimeLaw(model.problem.s, solution.w, p=spec.p, accel_start=spec.accel_start,
                  accel_end=spec.accel_end)
    profile = SpeedProfile(path=request.path, limits=request.limits, s=model.problem.s,
                           w=solution.w, solution=solution, law=law, speed_bound=model.bound,
                           request=request)
    check = profile.verify()
    if not check.ok:
        worst = ", ".join(f"{k} {r:.3f}×" for k, r in check.violations.items())
        warnings.warn(
            f"the planned trajectory exceeds limits beyond tolerance ({worst} of the limit); "
            "refine the grid (larger n or smaller ds) — see profile.verify()",
            LimitWarning, stacklevel=3,
        )
    return replace(profile, verification=check)

"""profile_from_waypoints(): from a list of (x, y) points to a sampled trajectory in one call."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TypedDict, Unpack

from numpy.typing import ArrayLike

from .core.limits import Limits
from .core.options import Backend, Refine, Standstill, VLimit
from .geometry import Path, SpanLimit, SpeedZone
from .geometry.fitting import DEFAULT_KIND
from .plan import plan
from .timing import Trajectory

__all__ = ["WaypointPlanOptions", "profile_from_waypoints"]


class WaypointPlanOptions(TypedDict, total=False):
    """The [`speedplan.plan`][speedplan.plan] keywords `profile_from_waypoints` passes on.

    ``n``, ``ds``, ``v_limit``, ``refine``, ``standstill``, ``backend``, ``stops``,
    ``spans`` and ``time_limit``, as for `speedplan.plan`; the zones and the boundary states
    are keywords of `profile_from_waypoints` itself.
    """

    n: int | None
    ds: float | None
    v_limit: VLimit | None
    refine: Refine
    standstill: Standstill
    backend: Backend
    stops: Sequence[float] | None
    spans: Sequence[SpanLimit] | None
    time_limit: float | None


def profile_from_waypoints(
    xy: ArrayLike,
    *,
    v_max: float,
    a_max: float,
    a_lat_max: float,
    j_max: float,
    a_decel: float | None = None,
    dt: float = 0.01,
    kind: str = DEFAULT_KIND,
    headings: ArrayLike | None = None,
    corner_radius: float | None = None,
    max_deviation: float | None = None,
    transition: float | None = None,
    zones: Sequence[SpeedZone] | None = None,
    v0: float = 0.0,
    a0: float = 0.0,
    vf: float = 0.0,
    af: float = 0.0,
    **plan_options: Unpack[WaypointPlanOptions],
) -> Trajectory:
    """Plan through waypoints and return the trajectory sampled every ``dt`` seconds.

    The waypoints are joined by a drivable path, by default straight legs with G2 corners
    that cut each waypoint by at most ``max_deviation`` (0.25 m), then planned with
    `speedplan.plan`. ``kind``, ``headings``, ``corner_radius``, ``max_deviation`` and
    ``transition`` are those of `speedplan.Path.from_waypoints` (an option that does not
    apply to ``kind`` raises `InvalidInputError`); the other keywords go to
    [`speedplan.plan`][speedplan.plan].

    Examples
    --------
    >>> import speedplan as sp
    >>> traj = sp.profile_from_waypoints([[0, 0], [8, 0], [12, 3]], v_max=2, a_max=1,
    ...                                  a_lat_max=1, j_max=0.5, dt=0.05)
    >>> bool(traj.v[0] == 0 and traj.v.max() <= 2 * 1.005), bool(abs(traj.a[-1]) < 1e-9)
    (True, True)
    """
    path = Path.from_waypoints(xy, kind, headings=headings, corner_radius=corner_radius,
                               max_deviation=max_deviation, transition=transition)
    limits = Limits(v_max=v_max, a_max=a_max, a_lat_max=a_lat_max, j_max=j_max,
                    a_decel=a_decel)
    profile = plan(path, limits, zones=zones, v0=v0, a0=a0, vf=vf, af=af, **plan_options)
    return profile.sample(dt)

"""A planning request: the arguments of [`speedplan.plan`][speedplan.plan], validated once."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..core.checks import as_array, as_scalar
from ..core.errors import InvalidInputError
from ..core.limits import Limits
from ..core.options import (
    BACKENDS,
    REACH_MODES,
    REFINE_MODES,
    STANDSTILL_MODES,
    Backend,
    Reach,
    Refine,
    Standstill,
    VLimit,
    check_option,
)
from ..geometry import Path, SpeedZone
from ..geometry.bounds import SpanLimit, check_spans, check_zones

__all__ = ["MIN_RELATIVE_LENGTH", "REACH_MODES", "STANDSTILL_MODES", "STATE_ROUNDING",
           "PlanRequest", "within_limit"]
#: Shortest path planned, relative to ``v_max² / a_max`` (4e-9 m for v_max = 2 m/s, a_max = 1
#: m/s²; relative, so that millimetres and metres agree). Far below any vehicle's resolution;
#: much shorter paths (nearly coincident waypoints) made the solvers fail with misleading
#: messages.
MIN_RELATIVE_LENGTH = 1e-9

#: A boundary speed or acceleration above its limit by at most this fraction of the limit is
#: taken at the limit: the rounding of a state read off a plan (measured up to 9e-9, e.g. an
#: order update started from the vehicle's planned state), far below any vehicle's
#: resolution. Anything more is refused as before.
STATE_ROUNDING = 1e-6


def within_limit(name: str, value: float, limit: float, unit: str, what: str) -> float:
    """``value``, or ``limit`` if ``value`` exceeds it by at most `STATE_ROUNDING`.

    Raises `InvalidInputError` naming ``name`` beyond that; ``what`` says
    which limit it is. ``limit`` may be negative (a lower limit, as ``-a_decel``: then
    "exceeds" means "falls below").

    Examples
    --------
    >>> within_limit("v0", 2.0000000004, 2.0, "m/s", "the speed bound")
    2.0
    >>> from speedplan import InvalidInputError
    >>> try:
    ...     within_limit("a0", -1.5, -1.0, "m/s²", "-a_decel")
    ... except InvalidInputError as exc:
    ...     print(str(exc)[:42])
    `a0`=-1.5 m/s² is beyond -a_decel = -1.0 m
    """
    beyond = value < limit if limit < 0 else value > limit
    if not beyond:
        return value
    if abs(value - limit) <= STATE_ROUNDING * abs(limit):
        return limit
    raise InvalidInputError(f"`{name}`={value!r} {unit} is beyond {what} = {limit!r} {unit}; "
                            "pass a value within the limits")


@dataclass(frozen=True)
class PlanRequest:
    """What [`speedplan.plan`][speedplan.plan] was asked, after validation (see its parameters).

    Build it with `create`, which raises [`InvalidInputError`][speedplan.InvalidInputError] naming
    the argument at fault; `speedplan.plan_many` uses it to check every job before
    shipping any.

    Examples
    --------
    >>> from speedplan import Limits, Path
    >>> from speedplan.model import PlanRequest
    >>> req = PlanRequest.create(Path.from_waypoints([[0, 0], [5, 0]], kind="polyline"),
    ...                          Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5), v0=0.5)
    >>> req.v0, req.smooth_standstill
    (0.5, True)
    """

    path: Path
    limits: Limits
    n: int | None = None
    ds: float | None = None
    v0: float = 0.0
    a0: float = 0.0
    vf: float = 0.0
    af: float = 0.0
    zones: tuple[SpeedZone, ...] | None = None
    v_limit: VLimit | None = None
    refine: Refine = "auto"
    standstill: Standstill = "smooth"
    backend: Backend = "auto"
    stops: tuple[float, ...] = ()
    spans: tuple[SpanLimit, ...] = ()
    reach: Reach = "max_jerk"  # one of REACH_MODES; set by plan(), not by callers
    #: Jerk [m/s³] the jerk rows allow when a moving boundary state needs a hair more than
    #: ``limits.j_max`` (``None``: ``limits.j_max``): set by plan() for states just outside
    #: what ``j_max`` reaches, not by callers.
    state_jerk: float | None = None
    #: Jerk [m/s³] of the turn of a moving boundary state just outside what ``limits.j_max``
    #: reaches (`TurnLeg`: its acceleration brought to 0, the rest of the move with
    #: ``j_max``); ``None``: no such turn. Set by plan(), not by callers.
    turn_jerk: float | None = None

    @classmethod
    def create(cls, path: Path, limits: Limits, *, n: int | None = None,
               ds: float | None = None, v0: float = 0.0, a0: float = 0.0, vf: float = 0.0,
               af: float = 0.0, zones: Sequence[SpeedZone] | None = None,
               v_limit: VLimit | None = None, refine: Refine = "auto",
               standstill: Standstill = "smooth", backend: Backend = "auto",
               stops: ArrayLike | None = None,
               spans: Sequence[SpanLimit] | None = None) -> PlanRequest:
        """Check every argument; raise `InvalidInputError` naming a bad one.

        Each argument is checked at run time whatever its annotation says (an option string
        against its closed set, listing the valid values).
        """
        if not isinstance(path, Path):
            raise InvalidInputError(
                f"`path` must be a speedplan.Path; got {type(path).__name__} (build one with "
                "Path.from_waypoints, Path.from_segments, Path.from_nurbs or Path.from_linestring)"
            )
        if not isinstance(limits, Limits):
            raise InvalidInputError(
                f"`limits` must be a speedplan.Limits; got {type(limits).__name__}"
            )
        limits.check_range()
        refine = check_option("refine", refine, REFINE_MODES)
        standstill = check_option("standstill", standstill, STANDSTILL_MODES)
        backend = check_option("backend", backend, BACKENDS)
        if n is not None and ds is not None:
            raise InvalidInputError("pass at most one of `n` and `ds`")
        if n is not None and (isinstance(n, bool) or not isinstance(n, int | np.integer)
                              or n < 3):
            raise InvalidInputError(f"`n` must be an integer >= 3; got {n!r}")
        request = cls(
            path=path,
            limits=limits,
            n=None if n is None else int(n),
            ds=None if ds is None else as_scalar("ds", ds, positive=True),
            v0=as_scalar("v0", v0, nonnegative=True),
            a0=_acceleration("a0", as_scalar("a0", a0), limits),
            vf=as_scalar("vf", vf, nonnegative=True),
            af=_acceleration("af", as_scalar("af", af), limits),
            zones=None if zones is None else tuple(check_zones(zones)),
            v_limit=v_limit,
            refine=refine,
            standstill=standstill,
            backend=backend,
            stops=_check_stops(stops, float(path.length)),
            spans=tuple(check_spans(spans, float(path.length))),
        )
        request._check_accelerations()
        request._check_length()
        return request

    @property
    def jerk_limited(self) -> bool:
        """Whether the limits bound the jerk."""
        return math.isfinite(self.limits.j_max)  # read many times a plan: no numpy call

    def leg_jerk(self, v0: float, a0: float, vf: float, af: float) -> float:
        """The jerk [m/s³] of a leg (or stretch) between these states.

        ``state_jerk`` where one of them moves (a marginal state's looser jerk), else
        ``limits.j_max``: the looser jerk ends at the state's first rest.
        """
        if self.state_jerk is None or (v0 == 0.0 and a0 == 0.0 and vf == 0.0 and af == 0.0):
            return self.limits.j_max
        return self.state_jerk

    @property
    def smooth_standstill(self) -> bool:
        """Whether acceleration is 0 at a standstill (jerk-limited, ``standstill="smooth"``)."""
        return self.jerk_limited and self.standstill == "smooth"

    def _check_accelerations(self) -> None:
        if self.smooth_standstill:
            for vname, v, aname, a in (("v0", self.v0, "a0", self.a0),
                                       ("vf", self.vf, "af", self.af)):
                if v == 0.0 and a != 0.0:
                    raise InvalidInputError(
                        f"`{aname}`={a!r} with `{vname}`=0: a jerk-limited vehicle at rest has "
                        "zero acceleration; pass 0, or standstill='free' for the paper's model"
                    )

    def _check_length(self) -> None:
        length = float(self.path.length)
        min_length = MIN_RELATIVE_LENGTH * self.limits.v_max**2 / self.limits.a_max
        if not length >= min_length:
            raise InvalidInputError(
                f"`path` is {length:.3g} m long, shorter than {min_length:.3g} m "
                "(1e-9 v_max²/a_max): there is no motion to plan (nearly coincident "
                "waypoints?); skip the move or check the path"
            )


def _check_stops(stops: ArrayLike | None, length: float) -> tuple[float, ...]:
    """``stops`` as sorted positions strictly inside ``(0, length)`` [m]."""
    if stops is None:
        return ()
    arr = as_array("stops", stops, ndim=1)
    bad = arr[(arr <= 0.0) | (arr >= length)]
    if bad.size:
        raise InvalidInputError(
            f"`stops` must lie strictly inside the path (0, {length:.9g}) m; got {bad[0]!r} "
            "(the ends are always at the boundary states v0/vf)"
        )
    return tuple(float(s) for s in np.unique(arr))


def _acceleration(name: str, a: float, lim: Limits) -> float:
    """A boundary acceleration within ``[-a_decel, a_max]`` (see `within_limit`)."""
    a = within_limit(name, a, lim.a_max, "m/s²", "a_max")
    return within_limit(name, a, -lim.a_decel, "m/s²", "-a_decel")

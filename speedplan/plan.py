"""plan(): geometry -> speed bounds -> discrete solve -> time law, in one call."""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np

from ._checks import FloatArray, as_scalar, choice
from .errors import InfeasibleError, InvalidInputError, LimitWarning
from .geometry import Path, SpeedBound, SpeedZone
from .limits import Limits
from .solve import DiscreteProblem, solve_problem
from .solve.boundary import check_boundary_state, jerk_motion_w, max_jerk_envelope
from .solve.discrete import BACKENDS, REFINE_MODES
from .solve.grid import adaptive_grid, uniform_grid
from .timing import SpeedProfile, TimeLaw

__all__ = ["STANDSTILL_MODES", "SpeedBound", "plan"]

#: ``"smooth"``: acceleration is 0 at a standstill and jerk-limited from the first instant.
#: ``"free"``: the paper's model, where acceleration may jump at a standstill.
STANDSTILL_MODES = ("smooth", "free")
#: Shortest path planned, relative to ``v_max² / a_max`` (4e-9 m for v_max = 2 m/s, a_max = 1
#: m/s²; relative, so that millimetres and metres agree). Far below any vehicle's resolution;
#: much shorter paths (nearly coincident waypoints) made the solvers fail with misleading
#: messages.
MIN_RELATIVE_LENGTH = 1e-9
_NO_JERK_NODES = 1001


def _check_boundary(limits: Limits, v0: float, a0: float, vf: float, af: float,
                    standstill: str) -> None:
    for name, a in (("a0", a0), ("af", af)):
        if a > limits.a_max * (1 + 1e-12) or a < -limits.a_decel * (1 + 1e-12):
            raise InvalidInputError(
                f"`{name}`={a!r} m/s² is outside [-a_decel, a_max] = "
                f"[{-limits.a_decel!r}, {limits.a_max!r}]; pass an acceleration within the limits"
            )
    if standstill == "smooth" and np.isfinite(limits.j_max):
        for vname, v, aname, a in (("v0", v0, "a0", a0), ("vf", vf, "af", af)):
            if v == 0.0 and a != 0.0:
                raise InvalidInputError(
                    f"`{aname}`={a!r} with `{vname}`=0: a jerk-limited vehicle at rest has zero "
                    "acceleration; pass 0, or standstill='free' for the paper's model"
                )
    check_boundary_state(v0, a0, limits.j_max, end=False)
    check_boundary_state(vf, af, limits.j_max, end=True)


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
        :class:`~speedplan.errors.LimitWarning` is issued when :meth:`SpeedProfile.verify`
        finds a limit exceeded beyond its tolerance.

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
    if not isinstance(path, Path):
        raise InvalidInputError(
            f"`path` must be a speedplan.Path; got {type(path).__name__} (build one with "
            "Path.from_waypoints, Path.from_segments, Path.from_nurbs or Path.from_linestring)"
        )
    if not isinstance(limits, Limits):
        raise InvalidInputError(f"`limits` must be a speedplan.Limits; got {type(limits).__name__}")
    choice("refine", refine, REFINE_MODES)
    choice("standstill", standstill, STANDSTILL_MODES)
    choice("backend", backend, BACKENDS)
    if n is not None and ds is not None:
        raise InvalidInputError("pass at most one of `n` and `ds`")
    if n is not None and (isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 3):
        raise InvalidInputError(f"`n` must be an integer >= 3; got {n!r}")
    ds_ = None if ds is None else as_scalar("ds", ds, positive=True)
    v0 = as_scalar("v0", v0, nonnegative=True)
    vf = as_scalar("vf", vf, nonnegative=True)
    a0 = as_scalar("a0", a0)
    af = as_scalar("af", af)
    _check_boundary(limits, v0, a0, vf, af, standstill)
    L = float(path.length)
    min_length = MIN_RELATIVE_LENGTH * limits.v_max**2 / limits.a_max
    if not L >= min_length:
        raise InvalidInputError(
            f"`path` is {L:.3g} m long, shorter than {min_length:.3g} m (1e-9 v_max²/a_max): "
            "there is no motion to plan (nearly coincident waypoints?); skip the move or "
            "check the path"
        )
    zone_list = list(zones) if zones is not None else None
    bound = SpeedBound(path, limits, zone_list, v_limit)

    ends = bound(np.array([0.0, L]))
    for name, v, b, where in (("v0", v0, ends[0], 0.0), ("vf", vf, ends[1], L)):
        if v * v > b * (1 + 1e-9):
            raise InvalidInputError(
                f"`{name}`={v!r} m/s exceeds the speed bound {np.sqrt(b):.6g} m/s at "
                f"s={where:.6g} m (v_max, lateral acceleration or a zone); pass a lower speed"
            )
    jerk_limited = np.isfinite(limits.j_max)
    smooth = jerk_limited and standstill == "smooth"

    j = limits.j_max

    def envelope_cap(s: FloatArray, w: FloatArray) -> FloatArray:
        # Fastest jerk-limited motion leaving (v0, a0), and arriving at (vf, af) (time-reversed).
        if smooth:
            w = np.minimum(w, jerk_motion_w(s, v0, a0, j, limits.a_max))
            w = np.minimum(w, jerk_motion_w(L - s, vf, -af, j, limits.a_decel))
        return w

    def envelope_floor(s: FloatArray) -> FloatArray | None:
        # Slowest jerk-limited motion leaving a moving state (and arriving at one).
        if not smooth or (v0 == 0.0 and vf == 0.0):
            return None
        lo = np.zeros_like(s)
        if v0 > 0:
            lo = np.maximum(lo, jerk_motion_w(s, v0, min(a0, 0.0), -j, -limits.a_decel))
        if vf > 0:
            lo = np.maximum(lo, jerk_motion_w(L - s, vf, min(-af, 0.0), -j, -limits.a_max))
        return lo

    def capped(s: FloatArray) -> FloatArray:
        return envelope_cap(s, bound(s))

    if n is not None or ds_ is not None:
        s = uniform_grid(L, n=None if n is None else int(n), ds=ds_)
    elif jerk_limited:
        s = adaptive_grid(L, capped, a_max=limits.a_max, a_decel=limits.a_decel,
                          v_max=limits.v_max, j_max=limits.j_max, w_start=v0 * v0,
                          w_end=vf * vf)
    else:
        s = uniform_grid(L, n=_NO_JERK_NODES)
    w_max = envelope_cap(s, _node_bounds(bound, s))
    w_max[0] = max(w_max[0], v0 * v0)
    w_max[-1] = max(w_max[-1], vf * vf)
    if (w_max[1:-1] <= 0).any():
        i = int(np.flatnonzero(w_max[1:-1] <= 0)[0]) + 1
        raise InvalidInputError(
            f"the speed bound is 0 at s={s[i]:.6g} m inside the path (infinite curvature, e.g. "
            "a sharp polyline corner, or a zone with v_max=0); round the corners "
            "(Path.from_waypoints(..., kind='clothoid')) or split the path there"
        )
    m = s.size
    jerk = np.full(m - 2, limits.J)
    if smooth:
        _calibrate_standstill_rows(jerk, s, v0, a0, vf, af, limits.j_max)
    problem = DiscreteProblem(
        s=s, w_max=w_max,
        accel=np.full(m - 1, limits.A), decel=np.full(m - 1, limits.A_decel),
        jerk=jerk, w_start=v0 * v0, w_end=vf * vf, w_min=envelope_floor(s),
    )
    try:
        solution = solve_problem(problem, refine=refine, backend=backend)
    except InfeasibleError as exc:
        raise _explain(exc, problem, limits, v0, vf) from exc
    p = 0.75 if smooth else 1.0
    law = TimeLaw(s, solution.w, p=p, accel_start=a0 if v0 > 0 else None,
                  accel_end=af if vf > 0 else None)
    profile = SpeedProfile(
        path=path, limits=limits, s=s, w=solution.w, solution=solution, law=law,
        speed_bound=bound,
        options={"standstill": standstill, "v0": v0, "a0": a0, "vf": vf, "af": af,
                 "zones": zone_list, "refine": refine, "backend": backend},
    )
    check = profile.verify()
    profile.options["verification"] = check
    if not check.ok:
        worst = ", ".join(f"{k} {r:.3f}×" for k, r in check.violations.items())
        warnings.warn(
            f"the planned trajectory exceeds limits beyond tolerance ({worst} of the limit); "
            "refine the grid (larger n or smaller ds) — see profile.verify()",
            LimitWarning, stacklevel=2,
        )
    return profile


#: Jerk rows recalibrated next to a standstill (see :func:`_calibrate_standstill_rows`).
STANDSTILL_ROWS = 8


def _calibrate_standstill_rows(jerk: FloatArray, s: FloatArray, v0: float, a0: float,
                               vf: float, af: float, j_max: float) -> None:
    """Make the exact max-jerk start (stop) feasible for the first (last) jerk rows.

    From rest ``w ∝ s^{4/3}`` has ``w''`` singular at ``s = 0``; the three-point second
    difference overestimates it next to the standstill (by 17 % at the first node of a uniform
    grid, whatever the step), which would make the discrete optimum leave standstill later than
    the true one — a delay that shrinks only like ``h^{1/3}``. Scaling those few rows so that the
    max-jerk envelope meets them exactly removes the bias; the time law and ``verify()`` then
    check the realised jerk in continuous time.
    """
    k = min(STANDSTILL_ROWS, jerk.size)
    for at_rest, idx, dist in (
        (v0 == 0.0 and a0 == 0.0, slice(0, k + 2), s[: k + 2] - s[0]),
        (vf == 0.0 and af == 0.0, slice(s.size - k - 2, s.size), s[-1] - s[-k - 2 :]),
    ):
        if not at_rest:
            continue
        env = max_jerk_envelope(dist, j_max)
        sub = DiscreteProblem(s=s[idx], w_max=env, accel=np.ones(k + 1), decel=np.ones(k + 1),
                              jerk=np.full(k, np.inf))
        load = np.abs(sub.second_difference @ env) * np.sqrt(env[1:-1]) / (2.0 * j_max)
        rows = slice(0, k) if idx.start == 0 else slice(jerk.size - k, jerk.size)
        jerk[rows] *= np.maximum(1.0, load)


def _node_bounds(bound: Any, s: FloatArray, per_interval: int = 8) -> FloatArray:
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


def _explain(exc: InfeasibleError, problem: DiscreteProblem, limits: Limits, v0: float,
             vf: float) -> InfeasibleError:
    """Restate a discrete infeasibility in speeds and metres."""
    where = exc.s
    if where is None:
        return InfeasibleError(f"no speed law meets the request: {exc}", constraint=exc.constraint)
    i = int(np.argmin(np.abs(problem.s - where)))
    v_there = float(np.sqrt(problem.w_max[i]))
    if exc.constraint == "decel":
        msg = (f"cannot brake from v0={v0:.6g} m/s to {v_there:.6g} m/s (the speed bound at "
               f"s={where:.4g} m) under a_decel={limits.a_decel:.6g} m/s²")
    elif exc.constraint == "jerk":
        msg = (f"cannot brake from v0={v0:.6g} m/s to {v_there:.6g} m/s (the speed bound at "
               f"s={where:.4g} m) under j_max={limits.j_max:.6g} m/s³ and "
               f"a_decel={limits.a_decel:.6g} m/s²")
    elif exc.constraint == "accel":
        msg = (f"cannot reach vf={vf:.6g} m/s at the end from {v_there:.6g} m/s (the speed bound "
               f"at s={where:.4g} m) under a_max={limits.a_max:.6g} m/s²")
    else:
        msg = str(exc)
    return InfeasibleError(msg, constraint=exc.constraint, s=where)

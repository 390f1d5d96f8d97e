"""RouteProfile: the stop-to-stop speed profiles of a route, stitched into one motion."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike

from .._version import __version__
from ..core.checks import FloatArray, as_array
from ..core.errors import InvalidInputError
from ..timing import SpeedProfile, Trajectory, Verification
from ..timing.profile import sample_times
from ..timing.rotation import Turn
from ..timing.trajectory import COLUMNS
from ..timing.verify import LIMIT_NAMES, LimitCheck
from .route import Route

__all__ = ["RouteProfile", "RouteTrajectory", "RouteTurn"]

#: Samples per turn where `RouteProfile.verify` evaluates its yaw rate and acceleration
#: (the ends of the speed-up and slow-down included).
TURN_SAMPLES = 64


@dataclass(frozen=True)
class RouteTurn:
    """A turn on the spot on a released node of a route (the vehicle stands, v = 0).

    Attributes
    ----------
    node : int
        Index of the node in ``route.base_nodes``; -1 for a turn where the motion starts
        between two nodes (``plan_route(..., heading0=...)`` with the vehicle standing).
    s : float
        Its position along the route [m].
    turn : Turn
        The rotation ([`Turn`][speedplan.timing.rotation.Turn]: ``start``, ``angle``,
        ``duration``, ``at(t)``).
    rate_limit : float
        The yaw-rate limit it was planned under [rad/s]: the smaller of ``Limits.yaw_rate_max``
        and the adjacent edges' ``maxRotationSpeed`` (``inf``: none).
    """

    node: int
    s: float
    turn: Turn
    rate_limit: float

    @property
    def duration(self) -> float:
        """Time of the turn [s]."""
        return self.turn.duration


@dataclass(frozen=True)
class RouteTrajectory(Trajectory):
    """A [`Trajectory`][speedplan.Trajectory] along a route, with the edge each sample is on.

    Attributes
    ----------
    edge : ndarray
        Index into ``route.edges`` of the edge under the vehicle (at a node, the edge after
        it); the ids are in ``metadata["edge_ids"]``. Exported as the last column.
    """

    edge: FloatArray = field(default_factory=lambda: np.zeros(0))

    @property
    def units(self) -> dict[str, str]:
        """`COLUMNS` and ``edge``."""
        return {**COLUMNS, "edge": "1"}


@dataclass(frozen=True, eq=False)
class RouteProfile:
    """The minimum-time motion along a route: one [`SpeedProfile`][speedplan.SpeedProfile] per leg.

    The vehicle stops between legs (at `Route.stop_s`) and drives through every other
    node; each leg was planned on its own (see [`speedplan.plan_route`][speedplan.plan_route]).

    Attributes
    ----------
    route : Route
        What was planned.
    legs : tuple of SpeedProfile
        One per stop-to-stop leg from [`start_s`][speedplan.RouteProfile] on, in order.
    leg_starts : tuple of float
        Where each leg starts along ``route.path`` [m]; the last leg ends at the route's end.
    start_s : float
        Where the motion starts along the route [m] (0, or where an order update took over).
    turns : tuple of RouteTurn
        The turns on the spot, in order: where the heading must change on a node the vehicle
        stands still and rotates (a corner it may not cut, a node ``theta``, a change of edge
        orientation); their time is in `node_times`, `node_leave_times`, every
        later time and [`sample`][speedplan.RouteProfile.sample].
    """

    route: Route
    legs: tuple[SpeedProfile, ...]
    leg_starts: tuple[float, ...]
    start_s: float = 0.0
    turns: tuple[RouteTurn, ...] = ()

    def __post_init__(self) -> None:
        if not self.legs or len(self.legs) != len(self.leg_starts):
            raise InvalidInputError("a RouteProfile needs one leg start per leg, and a leg")

    @property
    def duration(self) -> float:
        """Time from `start_s` to the end of the route [s], the last turn included."""
        return float(self._phases[1][-1])

    @cached_property
    def _phases(self) -> tuple[tuple[tuple[str, int], ...], FloatArray, FloatArray]:
        """The motion's phases, their start times and their heading offsets.

        Phases in order (``("leg", j)`` or ``("turn", i)``); start times then the end [s];
        per phase the multiple of 2π added to its heading so that it continues the previous.
        """
        keyed = [((self.leg_starts[j], 1, j), ("leg", j)) for j in range(len(self.legs))]
        keyed += [((t.s, 0, i), ("turn", i)) for i, t in enumerate(self.turns)]
        order = tuple(p for _, p in sorted(keyed))
        times = [0.0]
        offsets = []
        heading: float | None = None
        for kind, i in order:
            if kind == "leg":
                leg = self.legs[i]
                ends = leg.at(np.array([0.0, leg.duration])).heading
                first, last, span = float(ends[0]), float(ends[-1]), leg.duration
            else:
                turn = self.turns[i].turn
                first, last, span = turn.start, turn.end, turn.duration
            shift = 0.0 if heading is None else 2 * np.pi * round((heading - first) / (2 * np.pi))
            offsets.append(shift)
            heading = last + shift
            times.append(times[-1] + span)
        out_t, out_o = np.array(times), np.array(offsets)
        out_t.flags.writeable = False
        out_o.flags.writeable = False
        return order, out_t, out_o

    @cached_property
    def leg_times(self) -> FloatArray:
        """Start time of each leg, then the duration [s] (turns on the spot included)."""
        order, times, _ = self._phases
        out = np.array([times[p] for p, (kind, _) in enumerate(order) if kind == "leg"]
                       + [times[-1]])
        out.flags.writeable = False
        return out

    @cached_property
    def turn_times(self) -> FloatArray:
        """Start time of each of [`turns`][speedplan.RouteProfile] [s]."""
        order, times, _ = self._phases
        out = np.zeros(len(self.turns))
        for p, (kind, i) in enumerate(order):
            if kind == "turn":
                out[i] = times[p]
        out.flags.writeable = False
        return out

    @cached_property
    def _node_arrive_leave(self) -> tuple[FloatArray, FloatArray]:
        node_s = self.route.node_s
        arrive = np.full(node_s.size, np.nan)
        tol = 1e-9 * max(self.route.length, 1.0)
        for k, s in enumerate(node_s):
            if s < self.start_s - tol:
                continue
            j = self._leg_holding(float(s))
            leg = self.legs[j]
            local = np.clip(float(s) - self.leg_starts[j], 0.0, leg.path.length)
            arrive[k] = self.leg_times[j] + float(leg.law.time_at(np.array([local]))[0])
        leave = arrive.copy()
        at_node: dict[int, list[int]] = {}
        for i, turn in enumerate(self.turns):
            if turn.node >= 0:  # -1: a turn where the motion starts between two nodes
                at_node.setdefault(turn.node, []).append(i)
        for k, idx in at_node.items():
            arrive[k] = min(self.turn_times[i] for i in idx)
            leave[k] = max(self.turn_times[i] + self.turns[i].duration for i in idx)
        arrive.flags.writeable = False
        leave.flags.writeable = False
        return arrive, leave

    @property
    def node_times(self) -> FloatArray:
        """When the vehicle arrives on each released node [s from the start], in order.

        ``NaN`` for the nodes behind `start_s` (already passed when an order update
        took over); non-decreasing from there. Where the vehicle turns on the spot on a node,
        it leaves at `node_leave_times`; every later time includes the turn.
        """
        return self._node_arrive_leave[0]

    @property
    def node_leave_times(self) -> FloatArray:
        """When the vehicle leaves each released node [s].

        Its arrival plus its turns on the spot (the time of blocking actions is not known to
        the planner and not included); the last entry is `duration`.
        """
        return self._node_arrive_leave[1]

    def _leg_holding(self, s: float) -> int:
        """The leg whose stretch holds ``s`` (the earlier at a stop between two legs)."""
        starts = np.asarray(self.leg_starts)
        return int(np.clip(np.searchsorted(starts, s, side="left") - 1, 0, len(self.legs) - 1))

    @property
    def status(self) -> str:
        """The worst status of the legs.

        ``"limits_exceeded"``, else ``"relaxed"``, ``"scaled"`` or ``"refined"`` if a leg has
        it, else ``"optimal"``.
        """
        statuses = {leg.status for leg in self.legs}
        for worst in ("limits_exceeded", "relaxed", "scaled", "refined"):
            if worst in statuses:
                return worst
        return "optimal"

    @property
    def gap(self) -> float:
        """Certified relative gap of the whole motion.

        ``(Σ objective - Σ lower bound) / Σ lower bound`` over the legs' discrete problems.
        """
        lower = sum(leg.solution.lower_bound for leg in self.legs)
        upper = sum(leg.solution.objective for leg in self.legs)
        return float((upper - lower) / lower) if lower > 0 else 0.0

    def verify(self) -> Verification:
        """The legs' checks of the continuous trajectory against every limit, and the turns'.

        Each turn on the spot is checked for its yaw rate (against
        `RouteTurn.rate_limit`), yaw acceleration (``"yaw_acc"``, against
        ``Limits.yaw_acc_max``) and, with a ``Limits.yaw_jerk_max``, yaw jerk (``"yaw_jerk"``),
        sampled at `TURN_SAMPLES` times and the ends of its pieces.
        """
        return Verification.merged([leg.verify() for leg in self.legs] + self._turn_checks())

    @property
    def verification(self) -> Verification:
        """The checks `speedplan.plan` made of each leg, merged with the turns'."""
        return Verification.merged([leg.verification or leg.verify() for leg in self.legs]
                                   + self._turn_checks())

    def _turn_checks(self) -> list[Verification]:
        """One `Verification` per turn: its yaw rate, acceleration and jerk.

        Rate and acceleration sampled (the ends of every piece included), the jerk from
        differences of the sampled acceleration.
        """
        out = []
        limits = self.legs[0].limits
        for turn in self.turns:
            t0 = turn.turn.breaks
            t = np.unique(np.concatenate((np.linspace(0.0, turn.duration, TURN_SAMPLES), t0,
                                          np.nextafter(t0, np.inf))))
            t = t[t <= turn.duration]
            _, rate, acc = turn.turn.at(t)
            peak_rate, peak_acc = float(np.max(np.abs(rate))), float(np.max(np.abs(acc)))
            # The vehicle stands: every other quantity is 0 during the turn.
            checks = {k: LimitCheck(k, ratio=0.0, maximum=0.0, where_s=turn.s)
                      for k in LIMIT_NAMES}
            checks["yaw_rate"] = LimitCheck(
                "yaw_rate", ratio=(peak_rate / turn.rate_limit if np.isfinite(turn.rate_limit)
                                   else 0.0),
                maximum=peak_rate, limit=turn.rate_limit, where_s=turn.s)
            checks["yaw_acc"] = LimitCheck("yaw_acc", ratio=peak_acc / limits.yaw_acc_max,
                                           maximum=peak_acc, limit=limits.yaw_acc_max,
                                           where_s=turn.s)
            if np.isfinite(limits.yaw_jerk_max):  # without a limit the acceleration steps
                step = np.diff(t)
                wide = step > 1e-9
                jerk = float(np.max(np.abs(np.diff(acc)[wide] / step[wide]), initial=0.0))
                checks["yaw_jerk"] = LimitCheck("yaw_jerk", ratio=jerk / limits.yaw_jerk_max,
                                                maximum=jerk, limit=limits.yaw_jerk_max,
                                                where_s=turn.s)
            else:
                del checks["yaw_jerk"]
            out.append(Verification(checks))
        return out

    # ---- sampling in time -------------------------------------------------------------------
    def edge_at(self, s: ArrayLike) -> FloatArray:
        """Index into ``route.edges`` of the edge at arc lengths ``s`` along the route."""
        q = as_array("s", s)
        node_s = self.route.node_s
        n_edges = len(self.route.base_edges)
        idx = np.clip(np.searchsorted(node_s, q, side="right") - 1, 0, n_edges - 1)
        out: FloatArray = idx.astype(np.float64)
        return out

    def at(self, t: ArrayLike) -> RouteTrajectory:
        """States at times ``t`` [s from the start] (clipped to ``[0, duration]``).

        During a turn on the spot the vehicle stands on its node (``v``, ``a``, ``j`` and the
        lateral columns 0) while ``heading`` and ``yaw_rate`` follow the turn; the heading is
        continuous over the whole motion.
        """
        order, starts_t, offsets = self._phases
        times = np.clip(np.atleast_1d(as_array("t", t)), 0.0, self.duration)
        p = np.clip(np.searchsorted(starts_t, times, side="right") - 1, 0, len(order) - 1)
        parts: dict[str, list[FloatArray]] = {}
        index = []
        for k in np.unique(p):
            sel = np.flatnonzero(p == k)
            kind, i = order[k]
            local = times[sel] - starts_t[k]
            if kind == "leg":
                cols = self.legs[i].at(local).to_dict()
                cols["s"] = cols["s"] + self.leg_starts[i]
            else:
                cols = self._turn_columns(i, local)
            cols["heading"] = cols["heading"] + offsets[k]
            for name, values in cols.items():
                parts.setdefault(name, []).append(np.asarray(values, dtype=np.float64))
            index.append(sel)
        flat = np.concatenate(index)
        inverse = np.empty_like(flat)
        inverse[flat] = np.arange(flat.size)
        out = {name: np.concatenate(values)[inverse] for name, values in parts.items()}
        out["t"] = times
        return RouteTrajectory(**out, edge=self.edge_at(out["s"]), metadata=self._metadata())

    def _turn_columns(self, i: int, local: FloatArray) -> dict[str, FloatArray]:
        """The trajectory's columns during turn ``i`` at its own times ``local`` [s]."""
        turn = self.turns[i]
        heading, rate, _ = turn.turn.at(local)
        path = self.route.path
        point = np.asarray(path.point(turn.s), dtype=np.float64).reshape(2)
        zero = np.zeros(local.size)
        # The driving direction of the edge the vehicle leaves on (the one it came on at the end).
        direction = float(np.asarray(path.direction(turn.s)).ravel()[0])
        return {"t": local, "s": np.full(local.size, turn.s), "x": np.full(local.size, point[0]),
                "y": np.full(local.size, point[1]), "heading": heading,
                "curvature": zero, "v": zero, "a": zero, "j": zero, "a_lat": zero,
                "yaw_rate": rate, "j_lat": zero, "direction": np.full(local.size, direction)}

    def sample(self, dt: float = 0.01) -> RouteTrajectory:
        """The motion sampled every ``dt`` seconds from 0; the last sample is at the end.

        Parameters
        ----------
        dt : float
            Sampling period [s], > 0.
        """
        traj = self.at(sample_times(self.duration, dt))
        return replace(traj, metadata={**traj.metadata, "dt": float(dt)})

    def _metadata(self) -> dict[str, object]:
        route = self.route
        return {
            "speedplan_version": __version__,
            "duration": self.duration,
            "status": self.status,
            "gap": self.gap,
            "start_s": self.start_s,
            "order_id": route.order_id,
            "order_update_id": route.order_update_id,
            "node_ids": [n.node_id for n in route.base_nodes],
            "node_s": route.node_s.tolist(),
            "node_times": [None if np.isnan(x) else float(x) for x in self.node_times],
            "node_leave_times": [None if np.isnan(x) else float(x)
                                 for x in self.node_leave_times],
            "stop_s": route.stop_s.tolist(),
            "edge_ids": [e.edge_id for e in route.base_edges],
            "limits": self.legs[0].limits,
        }

    def __repr__(self) -> str:
        return (f"RouteProfile(duration={self.duration:.6g} s, length={self.route.length:.6g} m, "
                f"legs={len(self.legs)}, status={self.status!r})")
